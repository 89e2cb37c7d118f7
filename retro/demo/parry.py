"""Demo step of the reference geometry: the parry pipeline on its built-in script."""

from __future__ import annotations

from pathlib import Path

from retro.render.parry import DEFAULT_FRAMES, DEFAULT_SCRIPT, write_parry


def parry_sequence(out_dir: Path) -> list[str]:
    """`retro demo` step: the built-in parry script."""
    run = write_parry(out_dir, DEFAULT_SCRIPT, DEFAULT_FRAMES, source="built-in script")
    counts = {k: sum(e.kind == k for e in run.events) for k in ("window", "parry", "hit", "whiff", "expired")}
    return [f"script: {DEFAULT_SCRIPT}",
            "events: " + " ".join(str(e) for e in run.events),
            ", ".join(f"{v} {k}" for k, v in counts.items()),
            f"wrote {run.files[0].name} ({len(run.states)} frames) and {len(run.files) - 2} event frames as PNG"]
