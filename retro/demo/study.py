"""`retro demo` step: the speed/accuracy chart on the reduced corpus (a few seconds)."""

from __future__ import annotations

from pathlib import Path

from retro.analysis.study.chart_run import run_chart, summary_lines

DEMO_SHAPES = ("ball", "bar")  # 3 pairs, 5781 cases: the full study is `retro chart`


def chart_step(out_dir: Path) -> list[str]:
    output = run_chart(out_dir / "chart", shape_names=DEMO_SHAPES, cost_samples=16)
    return summary_lines(output)
