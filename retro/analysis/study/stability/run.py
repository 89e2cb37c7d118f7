"""`retro stability`: every part of the stability study, written as charts, CSVs and one Markdown report."""

from __future__ import annotations

import time
from dataclasses import astuple, dataclass, fields
from pathlib import Path

from retro.analysis.study.corpus import load_shapes
from retro.analysis.study.csvdata import csv_text
from retro.progress import Progress, quiet
from retro.fileio import output_folder, write_atomic

REDUCED_SPEEDS = tuple(range(1, 25))
FULL_SPEEDS = tuple(range(1, 65))
OUTPUT_NAMES = ("tunnelling.csv", "tunnelling.png", "wrap.csv", "wrap.png", "ranges.csv", "edges.csv",
                "latch_pitfalls.csv", "stability.md")  # checked against the inputs before the run


@dataclass(frozen=True)
class StabilityOutput:
    files: list[Path]
    lines: list[str]
    seconds: float


def _csv(rows: list) -> str:
    if not rows:
        return ""
    return csv_text([f.name for f in fields(rows[0])], (["" if v is None else v for v in astuple(r)] for r in rows))


def _md_table(header: list[str], body: list[list[object]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in body]
    return "\n".join(lines) + "\n"


def _verdict_text(hit: float | None) -> str:
    if hit is None:
        return ""
    if hit in (0.0, 1.0):
        return "hit" if hit else "no"
    return f"hit in {100 * hit:.1f}% of alignments"


def edges_markdown(rows: list) -> str:
    """Two tables (boxes, circles; the swept cases with the boxes): a row per test, a column per
    case; a test with no answer on any of a table's cases is left out of it."""
    by = {(r.case, r.test): r.hit for r in rows}
    cases = list(dict.fromkeys(r.case for r in rows))
    tests = list(dict.fromkeys(r.test for r in rows))
    out = []
    for chosen in ([c for c in cases if not c.startswith("circle")], [c for c in cases if c.startswith("circle")]):
        used = [t for t in tests if any((c, t) in by for c in chosen)]
        out.append(_md_table(["test"] + chosen, [[t] + [_verdict_text(by.get((c, t))) for c in chosen] for t in used]))
    return "\n".join(out)


def run_stability(out_dir: Path, reduced: bool = False, progress: Progress = quiet,
                  methods: tuple | None = None, engine: str = "auto") -> StabilityOutput:
    from retro.analysis.study.methods import METHODS

    methods = METHODS if methods is None else tuple(methods)
    output_folder(out_dir, OUTPUT_NAMES)
    start = time.perf_counter()
    report = _Report(out_dir, ["# Stability: where each method breaks\n"], [], [])
    _tunnelling(report, reduced, methods, progress)
    _wrap(report, reduced, progress)
    _ranges(report, reduced, engine, progress)
    _edges(report, methods, progress)
    _latch(report, progress)
    report.files.append(write_atomic(out_dir / "stability.md", "".join(report.md)))
    return StabilityOutput(files=report.files, lines=report.summary, seconds=time.perf_counter() - start)


@dataclass
class _Report:
    """What the sections add to: the files written, the Markdown, the summary lines."""

    out_dir: Path
    md: list[str]
    files: list[Path]
    summary: list[str]


def _tunnelling(report: _Report, reduced: bool, methods: tuple, progress: Progress) -> None:
    from retro.analysis.study.stability import charts, tunnelling

    out_dir, md, files, summary = report.out_dir, report.md, report.files, report.summary
    mover = load_shapes(["bullet"])[0]
    speeds = REDUCED_SPEEDS if reduced else FULL_SPEEDS
    progress("stability: tunnelling")
    tunnel = tunnelling.tunnelling_table(mover, speeds=speeds, methods=methods)
    files.append(write_atomic(out_dir / "tunnelling.csv", _csv(tunnel)))
    files.append(write_atomic(out_dir / "tunnelling.png", charts.tunnelling_chart(tunnel, "4x4 bullet sprite", methods)))
    groups = list(dict.fromkeys(r.method for r in tunnel))
    body = [[charts.group_label(g, methods)] + [tunnelling.safe_speed(tunnel, g, t) for t in tunnelling.THICKNESSES]
            for g in groups]
    md.append("## Tunnelling\n\nHighest speed (px/frame, tested up to "
              f"{max(speeds)}) at which a 4x4 bullet never passes through a wall of the given thickness "
              "unseen (every start phase tried):\n\n")
    md.append(_md_table(["method"] + [f"wall {t} px" for t in tunnelling.THICKNESSES], body))
    md.append("\n![tunnelling](tunnelling.png)\n\n")
    thinnest = min(tunnelling.THICKNESSES)
    summary.append(f"tunnelling (highest speed with no miss, {thinnest} px wall, px/frame): "
                   + "; ".join(f"{charts.group_label(g, methods)} {tunnelling.safe_speed(tunnel, g, thinnest)}"
                               for g in groups))


def _wrap(report: _Report, reduced: bool, progress: Progress) -> None:
    from retro.analysis.study.stability import charts, ranges, wrap

    out_dir, md, files, summary = report.out_dir, report.md, report.files, report.summary
    progress("stability: coordinate wrap")
    wrap_rows, maps = wrap.wrap_table()
    files.append(write_atomic(out_dir / "wrap.csv", _csv(wrap_rows)))
    files.append(write_atomic(out_dir / "wrap.png", charts.wrap_chart(maps, wrap_rows)))
    md.append("## Coordinate wrap\n\nTwo full sprites at every pair of X register values (0-511, "
              "262,144 cases per row); the chip's answer from the VIC-II model:\n\n")
    md.append(_md_table(["video", "software test", "software says hit, chip shows none", "chip latches, software misses",
                         "first example (xa, xb)"],
                        [[r.video.upper(), r.test, r.software_only, r.hardware_only,
                          r.example_software_only or r.example_hardware_only] for r in wrap_rows]))
    routine_wrap = ranges.wrap_routine_rows(reduced=reduced)
    if routine_wrap:
        md.append("\nThe 6502 routines across the boundary, run in the emulator:\n\n")
        md.append(_md_table(["routine", "inputs", "cases", "mismatches against the 9-bit truth", "example"],
                            [[r.routine, r.inputs, r.cases, r.mismatches, r.example or ""] for r in routine_wrap]))
    md.append("\n![wrap](wrap.png)\n\n")
    pal9 = next(r for r in wrap_rows if r.video == "pal" and r.test.startswith("9-bit"))
    summary.append(f"wrap: on PAL a 9-bit box test disagrees with the chip in {pal9.software_only + pal9.hardware_only} "
                   "of 262,144 X pairs (see wrap.png)")


def _ranges(report: _Report, reduced: bool, engine: str, progress: Progress) -> None:
    from retro.analysis.study.stability import ranges

    out_dir, md, files = report.out_dir, report.md, report.files
    progress("stability: arithmetic range")
    range_rows = ranges.range_rows(reduced=reduced, progress=progress, engine=engine)
    files.append(write_atomic(out_dir / "ranges.csv", _csv(range_rows)))
    md.append("## Arithmetic range\n\n")
    md.append("Found by running the assembly (`retro check`'s domain search: structured and random cases, "
              + ("bounded" if reduced else "with the exhaustive sweeps of `retro check --exhaustive`") + "):\n\n")
    md.append(_md_table(["routine", "cases", "count", "wrong answers", "finding"],
                        [[r.routine, r.searched, r.cases, r.wrong, r.domain] for r in range_rows]))
    md.append("\n")


def _edges(report: _Report, methods: tuple, progress: Progress) -> None:
    from retro.analysis.study.stability import edges

    out_dir, md, files = report.out_dir, report.md, report.files
    progress("stability: edge conventions")
    edge_rows = edges.edge_table(methods)
    files.append(write_atomic(out_dir / "edges.csv", _csv(edge_rows)))
    md.append("## Edge conventions\n\n")
    md.append(edges_markdown(edge_rows))
    md.append("\n")


def _latch(report: _Report, progress: Progress) -> None:
    from retro.analysis.study.stability import latch_pitfalls

    out_dir, md, files, summary = report.out_dir, report.md, report.files, report.summary
    progress("stability: latch pitfalls")
    ship, ball = load_shapes(["ship", "ball"])
    found = latch_pitfalls.pitfalls(ship, ball)
    flat = [(p.scenario, p.kind, p.truth, "; ".join(f"frame {r.frame} line {r.line}: ${r.value:02X}" for r in p.reads),
             p.conclusion) for p in found]
    files.append(write_atomic(out_dir / "latch_pitfalls.csv",
                              csv_text(["scenario", "kind", "truth", "reads", "conclusion"], flat)))
    md.append("## Latch pitfalls\n\nA ship (sprite 0) and balls, driven through the VIC-II device; reads of "
              "$D01E at the raster lines shown:\n\n")
    md.append(_md_table(["scenario", "what happened", "reads of $D01E", "what the program concludes", "error"],
                        [[s, t, r, c, k] for s, k, t, r, c in flat]))
    summary.append("latch: " + ", ".join(f"{p.scenario} -> {p.kind}" for p in found))
