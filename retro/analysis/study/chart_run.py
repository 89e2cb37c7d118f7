"""`retro chart`: run the study on the corpus and write the chart, the CSV and the Markdown table."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

from retro.analysis.study import report
from retro.workers import Workers
from retro.analysis.study.corpus import DEFAULT_SHAPES, REDUCED_SHAPES, load_shapes
from retro.analysis.study.evaluate import evaluate
from retro.progress import Progress, quiet
from retro.analysis.study.methods import METHODS, Method
from retro.fileio import output_folder, write_atomic

# Cases per pair whose 6502 cycles are measured. The full run measures every case of every pair
# (69,372 calls per routine on the default corpus: about 20 s of py65 for all the routines on two
# cores, benchmarks/study_speed.py); a method whose calls are costly to set up caps its own sample
# (Method.max_cost_samples: the latch needs a VIC-II frame per call). The reduced run takes an evenly
# spread sample of each pair's offsets (every k-th case in row-major order).
FULL_COST_SAMPLES: int | None = None  # every case
REDUCED_COST_SAMPLES = 24
AUTO = "auto"

CSV_NAME = "study.csv"
MARKDOWN_NAME = "study.md"
OVERALL_PNG = "study_overall.png"
PAIRS_PNG = "study_pairs.png"
PER_FRAME_CSV = "per_frame.csv"
PER_FRAME_MARKDOWN = "per_frame.md"
PER_FRAME_PNG = "per_frame.png"


@dataclass(frozen=True)
class ChartOutput:
    rows: list[report.FigureRow]
    files: list[Path]
    seconds: float
    per_frame: object = None  # per_frame.PerFrame with --per-frame


def run_chart(out_dir: Path, reduced: bool = False, workers: Workers | int | None = None, progress: Progress = quiet,
              shape_names: tuple[str, ...] | None = None, cost_samples: int | None | str = AUTO,
              methods: tuple[Method, ...] = METHODS, sprite_files: tuple[str, ...] = (),
              per_frame: bool = False, engine: str = "auto") -> ChartOutput:
    """The study on the corpus (the named shapes from sprites/, then every sprite of `sprite_files`)
    for the given methods. `cost_samples`: cases per pair whose cycles are measured (None: every
    case; AUTO: every case, or REDUCED_COST_SAMPLES with `reduced`). `per_frame`: the cost per frame
    too, from the same run's cycles per test (per_frame.py). `engine`: where the routines' calls run
    (retro.analysis.check.engines.batched)."""
    from retro.analysis.study.cost_runs import measure_costs
    from retro.analysis.study.sprites_io import load_sprite_files

    names = shape_names or (REDUCED_SHAPES if reduced else DEFAULT_SHAPES)
    shapes = load_shapes(names)
    shapes += load_sprite_files(sprite_files, taken={s.name for s in shapes})  # checked before any output
    output_folder(out_dir, (CSV_NAME, MARKDOWN_NAME, OVERALL_PNG, PAIRS_PNG)
                  + ((PER_FRAME_CSV, PER_FRAME_MARKDOWN, PER_FRAME_PNG) if per_frame else ()))
    start = time.perf_counter()
    table = evaluate(shapes, methods, workers=workers, progress=progress)
    samples = (REDUCED_COST_SAMPLES if reduced else FULL_COST_SAMPLES) if cost_samples == AUTO else cost_samples
    costs = measure_costs(shapes, samples=samples, workers=workers, progress=progress, methods=methods, engine=engine)
    rows = report.figure_rows(table, costs)
    shown = ", ".join(s.name for s in shapes)
    measured = "every case" if samples is None else f"{samples} evenly spread cases per pair"
    capped = [f"{m.key} {m.max_cost_samples}" for m in methods if m.max_cost_samples is not None and not m.host_only
              and (samples is None or m.max_cost_samples < samples)]
    note = (f"corpus: {shown} ({len(table.pairs)} pairs, {table.cases} cases); cycles measured in py65 on "
            f"{measured}" + (f" (at most: {', '.join(capped)} per pair)" if capped else ""))
    files = [
        write_atomic(out_dir / CSV_NAME, report.rows_to_csv(rows)),
        write_atomic(out_dir / MARKDOWN_NAME, markdown_report(rows, note, costs, methods)),
    ]
    from retro.analysis.study.chart import overall_chart, pairs_chart, styles_of

    styles = styles_of(methods)
    files.append(write_atomic(out_dir / OVERALL_PNG, overall_chart(rows, styles, note)))
    files.append(write_atomic(out_dir / PAIRS_PNG, pairs_chart(rows, styles)))
    frames = None
    if per_frame:
        frames = _per_frame(out_dir, shapes, methods, costs, rows, reduced, workers, progress, files, shown, engine)
    return ChartOutput(rows=rows, files=files, seconds=time.perf_counter() - start, per_frame=frames)


def _per_frame(out_dir: Path, shapes, methods, costs, rows, reduced, workers, progress, files, shown: str,
               engine: str):
    from retro.analysis.study import per_frame_report
    from retro.analysis.study.per_frame import PAL_BUDGET, per_frame
    from retro.analysis.study.per_frame_chart import per_frame_chart

    result = per_frame(methods, {k: c.overall for k, c in costs.items()}, shapes, reduced=reduced, workers=workers,
                       progress=progress, engine=engine)
    accuracy = {r.method: r.accuracy for r in rows if r.scope == report.ALL}
    note = (f"objects: the shapes {shown} in turn, on a field one byte wide; cycles per test from this run's "
            f"corpus, preparation from `retro check`, broad phases measured on {result.broad.layouts} layouts x "
            f"{result.broad.frames} frames per object count; budget: {PAL_BUDGET.label}")
    files.append(write_atomic(out_dir / PER_FRAME_CSV, per_frame_report.rows_to_csv(result.rows)))
    files.append(write_atomic(out_dir / PER_FRAME_MARKDOWN, per_frame_report.markdown(result, note, accuracy)))
    files.append(write_atomic(out_dir / PER_FRAME_PNG, per_frame_chart(result, note)))
    return result


def markdown_report(rows: list[report.FigureRow], note: str, costs: dict, methods: tuple[Method, ...] = METHODS) -> str:
    counted = "\n".join(f"- **{key}** ({cost.routine or 'no routine'}"
                        + (f", prepared by {cost.prepare}" if cost.prepare else "") + f"): {cost.counted}"
                        for key, cost in costs.items())
    rules = "\n".join(f"| {m.key} | {m.label} | {m.rule} | {m.origin} |" for m in methods)
    return (f"# Speed against accuracy\n\n{note}.\n\n## All pairs pooled\n\n" + report.markdown_table(rows)
            + "\n## The methods\n\n| key | label | rule | defined in |\n|---|---|---|---|\n" + rules + "\n"
            + "\n## What each cycle figure counts\n\n" + counted + "\n"
            + "\n## Accuracy per pair (* = on that pair's software Pareto front)\n\n" + report.markdown_pairs(rows))


def summary_lines(output: ChartOutput) -> list[str]:
    lines = []
    for r in output.rows:
        if r.scope != report.ALL:
            continue
        cycles = "host only" if r.host_only else (
            "not measured" if math.isnan(r.cycles_mean) else f"{r.cycles_mean:6.1f} cycles")
        lines.append(f"{r.label:<34} {cycles:>14}  accuracy {100 * r.accuracy:6.2f}%  "
                     f"FP {100 * r.fp_rate:5.1f}%  FN {100 * r.fn_rate:4.1f}%"
                     + ("  software Pareto front" if r.pareto_software else ""))
    if output.per_frame is not None:
        lines += per_frame_lines(output.per_frame)
    lines.append(f"wrote {', '.join(p.name for p in output.files)} in {output.seconds:.1f} s")
    return lines


def per_frame_lines(result) -> list[str]:
    """Where each method leaves the PAL frame and the line budget (typical frames), cheapest phase."""
    from retro.analysis.study.per_frame import PHASE_LABELS

    b = result.budget
    lines = [f"cost per frame ({b.label}: frame {float(b.frame_cycles):,.0f} cycles, {b.lines} lines "
             f"{float(b.lines_cycles):,.0f}): first object count over each budget, typical frame"]
    labels = {m.key: m.label for m in result.methods}
    for e in result.exits:
        frame = f"over {e.served}" if e.frame_typical is None else str(e.frame_typical)
        line = f"over {e.served}" if e.lines_typical is None else str(e.lines_typical)
        lines.append(f"  {labels.get(e.method, e.method):<34} {PHASE_LABELS[e.phase]:<27} frame at {frame:>7}, "
                     f"{b.lines} lines at {line:>7}" + ("" if e.served == max(x.served for x in result.exits)
                                                         else f" (serves at most {e.served} objects)"))
    return lines
