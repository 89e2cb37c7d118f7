"""Demo step of the VIC-II model: the two-balls scene, its latch values and its overlap image."""

from __future__ import annotations

from pathlib import Path

from retro.app.vic import DEMO_SCENE, report_lines, run_scene
from retro.paths import EXAMPLES_DIR


def latch_scene(out_dir: Path) -> list[str]:
    """`retro demo`: the two-balls scene, its latch values and its overlap image."""
    run = run_scene(EXAMPLES_DIR / DEMO_SCENE, png=out_dir / "vic_two_balls.png", scale=2)
    return [f"examples/{DEMO_SCENE}:"] + report_lines(run)[1:-1] + ["wrote vic_two_balls.png (overlap image)"]
