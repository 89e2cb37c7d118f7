"""The cost-per-frame figures as CSV (one row per method, phase and object count) and Markdown."""

from __future__ import annotations

from dataclasses import fields

from retro.analysis.study.broad_phase import MAX_OBJECTS, PHASES, SORT_X
from retro.analysis.study.csvdata import csv_records, csv_text
from retro.analysis.study.per_frame import ONCE, PHASE_CROSSING, PHASE_LABELS, FrameRow, PerFrame, cheapest

COLUMNS = [f.name for f in fields(FrameRow)]
SHOWN_COUNTS = (1, 2, 4, 8, 16, 24, 32, 48, 64)  # the object counts the Markdown tables show


def _cell(value) -> str:
    if isinstance(value, float):
        return repr(round(value, 4))
    return str(value)


def rows_to_csv(rows: list[FrameRow]) -> str:
    return csv_text(COLUMNS, ([_cell(getattr(r, c)) for c in COLUMNS] for r in rows))


def rows_from_csv(text: str) -> list[FrameRow]:
    types = {f.name: f.type for f in fields(FrameRow)}
    parse = {"int": int, "float": float, "str": str}
    return [FrameRow(**{c: parse[str(types[c])](row[c]) for c in COLUMNS}) for row in csv_records(text, COLUMNS)]


def _n(value: int | None, served: int = MAX_OBJECTS) -> str:
    if value is None:
        return f"over {served}" if served == MAX_OBJECTS else f"never (serves at most {served})"
    return str(value)


def markdown(result: PerFrame, note: str, accuracy: dict[str, float] | None = None) -> str:
    accuracy = accuracy or {}
    labels = {m.key: m.label for m in result.methods}
    counts = [n for n in SHOWN_COUNTS if any(r.objects == n for r in result.rows)]
    out = _intro(result, note)
    out += _measured_parts(result)
    out += _broad_phases(result, counts)
    out += _typical_frames(result, counts, labels)
    out += _exits(result, labels)
    out += _crossings(result, labels)
    out += _cheapest(result, accuracy)
    return "\n".join(out) + "\n"


def _intro(result: PerFrame, note: str) -> list[str]:
    b = result.budget
    frame, lines = float(b.frame_cycles), float(b.lines_cycles)
    out = [f"# Cost per frame\n\n{note}.\n",
           "frame(N) = prepare calls x the prepare routine's cycles + the broad phase's own cycles (its loops and a "
           "JSR per candidate pair) + candidate pairs x the method's cycles per test (RTS included). Typical: the "
           "means; worst: the dearest prepare call, the dearest test on every candidate, the dearest layout. "
           "Not counted: moving a pair's values into the test's registers and zero page.\n",
           f"Budgets: a {b.label} frame, {frame:,.0f} cycles; {b.lines} raster lines, {lines:,.0f} cycles.\n"]
    return out


def _measured_parts(result: PerFrame) -> list[str]:
    out = []
    out.append("\n## Measured parts\n\n| method | cycles per test, mean (max) | prepared by | per | cycles per prepare call |\n"
               "|---|---|---|---|---|")
    for m in result.methods:
        row = next(r for r in result.rows if r.method == m.key)
        prep = result.prepares.get(m.prepare) if m.prepare else None
        per = "frame (one call for all)" if m.once_per_frame else (m.prepare_per.replace("_", " ") if m.prepare else "-")
        out.append(f"| {m.label} | {row.test_cycles:.1f} ({row.test_cycles_max}) | {m.prepare or '-'} | {per} | "
                   + (f"{prep.mean:.1f} ({prep.min}-{prep.max})" if prep else "-") + " |")
    return out


def _broad_phases(result: PerFrame, counts: list[int]) -> list[str]:
    out = []
    sweeps = {}
    for m in result.methods:
        if m.once_per_frame:
            continue
        rows = {r.objects: r for r in result.rows if r.method == m.key and r.phase == SORT_X}
        key = tuple((round(rows[n].broad_cycles, 1), round(rows[n].candidates, 2)) for n in sorted(rows))
        sweeps.setdefault(key, []).append(m.key)
    out.append(f"\n## The broad phases as measured (asm/broad/broad_phase.s; the sweep on {result.broad.layouts} "
               f"layouts x {result.broad.frames} frames per count)\n\nDriver cycles (without the pair tests) and "
               "candidate pairs, mean over the layouts:\n\n| objects | " + " | ".join(map(str, counts)) + " |\n|---|"
               + "---|" * len(counts))
    brute = {n: result.broad.brute[n] for n in counts}
    out.append("| every pair: cycles | " + " | ".join(f"{brute[n].cycles:,}" for n in counts) + " |")
    out.append("| every pair: pairs | " + " | ".join(str(brute[n].candidates) for n in counts) + " |")
    for key, members in sweeps.items():
        first = members[0]
        rows = {r.objects: r for r in result.rows if r.method == first and r.phase == SORT_X}
        name = "/".join(members)
        out.append(f"| sweep ({name}): cycles | " + " | ".join(f"{rows[n].broad_cycles:,.0f}" for n in counts) + " |")
        out.append(f"| sweep ({name}): pairs | " + " | ".join(f"{rows[n].candidates:.1f}" for n in counts) + " |")
    return out


def _typical_frames(result: PerFrame, counts: list[int], labels: dict[str, str]) -> list[str]:
    out = []
    out.append("\n## Cycles per frame (typical)\n\n| method | phase | " + " | ".join(map(str, counts)) + " |\n|---|---|"
               + "---|" * len(counts))
    for key in dict.fromkeys((r.method, r.phase) for r in result.rows):
        rows = {r.objects: r for r in result.rows if (r.method, r.phase) == key}
        out.append(f"| {labels.get(key[0], key[0])} | {PHASE_LABELS[key[1]]} | "
                   + " | ".join(f"{rows[n].frame_cycles:,.0f}" if n in rows else "-" for n in counts) + " |")
    return out


def _exits(result: PerFrame, labels: dict[str, str]) -> list[str]:
    b = result.budget
    out = []
    out.append("\n## Where each method leaves the budget\n\nThe first object count whose frame is over the budget "
               "(typical / worst); \"over 64\": every count up to 64 fits.\n\n"
               f"| method | phase | {b.label} frame | {b.lines} raster lines |\n|---|---|---|---|")
    for e in result.exits:
        if e.served < MAX_OBJECTS and all(v is None for v in (e.frame_typical, e.frame_worst, e.lines_typical,
                                                               e.lines_worst)):
            fits = f"fits, for the {e.served} objects it can serve"
            out.append(f"| {labels.get(e.method, e.method)} | {PHASE_LABELS[e.phase]} | {fits} | {fits} |")
            continue
        out.append(f"| {labels.get(e.method, e.method)} | {PHASE_LABELS[e.phase]} | {_n(e.frame_typical, e.served)} / "
                   f"{_n(e.frame_worst, e.served)} | {_n(e.lines_typical, e.served)} / {_n(e.lines_worst, e.served)} |")
    return out


def _crossings(result: PerFrame, labels: dict[str, str]) -> list[str]:
    out = []
    out.append("\n## Where the curves cross\n\nFrom N objects on (up to 64), the first costs less per frame than "
               "the second (typical frames): the last change of their order; curves that never change order are "
               "not listed.\n")
    phases = [c for c in result.crossings if c.phase == PHASE_CROSSING]
    if phases:
        out.append("Sorting along X against every pair, per method:\n")
        out += [f"- {labels.get(c.cheaper, c.cheaper)}: " + ("the sweep" if c.sweep_wins else "every pair")
                + f" is cheaper from N = {c.objects}" for c in phases]
    for phase in PHASES:
        chosen = [c for c in result.crossings if c.phase == phase]
        out.append(f"\nBetween methods, {PHASE_LABELS[phase]}:\n")
        out += [f"- N = {c.objects}: {labels.get(c.cheaper, c.cheaper)} below {labels.get(c.dearer, c.dearer)}"
                for c in chosen] or ["- none: the order of the methods does not change"]
    return out


def _cheapest(result: PerFrame, accuracy: dict[str, float]) -> list[str]:
    out = []
    out.append("\n## The cheapest software method at each N\n\n| objects | method | phase | cycles per frame at the "
               "first N | accuracy |\n|---|---|---|---|---|")
    for first, last, r in cheapest(result.rows, accuracy=accuracy):
        acc = accuracy.get(r.method)
        out.append(f"| {first}-{last} | {r.label} | {PHASE_LABELS[r.phase]} | {r.frame_cycles:,.0f} | "
                   + (f"{100 * acc:.1f}%" if acc is not None else "-") + " |")
    exact = [k for k, a in accuracy.items() if a >= 1.0 and any(r.method == k and r.software for r in result.rows)]
    if exact:
        out.append("\nAmong the exact software methods (100% on the corpus):\n\n| objects | method | phase | cycles per "
                   "frame at the first N |\n|---|---|---|---|")
        for first, last, r in cheapest(result.rows, exact):
            out.append(f"| {first}-{last} | {r.label} | {PHASE_LABELS[r.phase]} | {r.frame_cycles:,.0f} |")
    once = [r for r in result.rows if r.phase == ONCE]
    if once:
        r = once[0]
        out.append(f"\n{r.label}: {r.frame_cycles:.0f} cycles a frame for up to {max(x.objects for x in once)} "
                   "objects (one read answers for all sprites; it does not say which pair collided).")
    return out
