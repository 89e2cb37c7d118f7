"""`retro chart`: run the study on the corpus and write the chart, the CSV and the Markdown table."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

from retro.analysis.study import report
from retro.analysis.study.corpus import DEFAULT_SHAPES, REDUCED_SHAPES, load_shapes
from retro.analysis.study.evaluate import Progress, evaluate, quiet
from retro.analysis.study.methods import METHODS
from retro.fileio import output_folder, write_atomic

# Cases per pair whose 6502 cycles are measured: a deterministic, evenly spread sample of the
# pair's offsets (every k-th case in row-major order). The full corpus is ~54,000 cases per method;
# measuring them all in py65 would take hours for the pixel routine.
FULL_COST_SAMPLES = 192
REDUCED_COST_SAMPLES = 24

CSV_NAME = "study.csv"
MARKDOWN_NAME = "study.md"
OVERALL_PNG = "study_overall.png"
PAIRS_PNG = "study_pairs.png"


@dataclass(frozen=True)
class ChartOutput:
    rows: list[report.FigureRow]
    files: list[Path]
    seconds: float


def run_chart(out_dir: Path, reduced: bool = False, workers: int | None = None, progress: Progress = quiet,
              shape_names: tuple[str, ...] | None = None, cost_samples: int | None = None) -> ChartOutput:
    from retro.analysis.study.cost_runs import measure_costs

    output_folder(out_dir)
    start = time.perf_counter()
    names = shape_names or (REDUCED_SHAPES if reduced else DEFAULT_SHAPES)
    shapes = load_shapes(names)
    table = evaluate(shapes, METHODS, workers=workers, progress=progress)
    samples = cost_samples or (REDUCED_COST_SAMPLES if reduced else FULL_COST_SAMPLES)
    costs = measure_costs(shapes, samples=samples, workers=workers, progress=progress)
    rows = report.figure_rows(table, costs)
    note = (f"corpus: {', '.join(names)} ({len(table.pairs)} pairs, {table.cases} cases); "
            f"cycles measured in py65 on {samples} evenly spread cases per pair")
    files = [
        write_atomic(out_dir / CSV_NAME, report.rows_to_csv(rows)),
        write_atomic(out_dir / MARKDOWN_NAME, markdown_report(rows, note, costs)),
    ]
    from retro.analysis.study.chart import overall_chart, pairs_chart

    files.append(write_atomic(out_dir / OVERALL_PNG, overall_chart(rows, note)))
    files.append(write_atomic(out_dir / PAIRS_PNG, pairs_chart(rows)))
    return ChartOutput(rows=rows, files=files, seconds=time.perf_counter() - start)


def markdown_report(rows: list[report.FigureRow], note: str, costs: dict) -> str:
    counted = "\n".join(f"- **{key}** ({cost.routine or 'no routine'}): {cost.counted}" for key, cost in costs.items())
    return (f"# Speed against accuracy\n\n{note}.\n\n## All pairs pooled\n\n" + report.markdown_table(rows)
            + "\n## What each cycle figure counts\n\n" + counted + "\n"
            + "\n## Accuracy per pair (* = on that pair's software Pareto front)\n\n" + report.markdown_pairs(rows))


def summary_lines(output: ChartOutput) -> list[str]:
    lines = []
    for r in output.rows:
        if r.scope != report.ALL:
            continue
        cycles = "host only" if r.host_only else (
            "not measured" if math.isnan(r.cycles_mean) else f"{r.cycles_mean:6.1f} cycles")
        lines.append(f"{r.label:<24} {cycles:>14}  accuracy {100 * r.accuracy:6.2f}%  "
                     f"FP {100 * r.fp_rate:5.1f}%  FN {100 * r.fn_rate:4.1f}%"
                     + ("  software Pareto front" if r.pareto_software else ""))
    lines.append(f"wrote {', '.join(p.name for p in output.files)} in {output.seconds:.1f} s")
    return lines
