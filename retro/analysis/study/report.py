"""The chart's figures as rows: one per (scope, method), scope a shape pair or ALL; CSV and Markdown."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

from retro.analysis.study.accuracy import Confusion
from retro.analysis.study.costs import MethodCost
from retro.analysis.study.csvdata import csv_records, csv_text
from retro.analysis.study.evaluate import AccuracyTable
from retro.analysis.study.pareto import pareto_front

ALL = "ALL"


@dataclass(frozen=True)
class FigureRow:
    scope: str  # shape pair "a+b", or ALL for the pooled corpus
    method: str
    label: str
    cases: int
    colliding: int
    tp: float
    fp: float
    tn: float
    fn: float
    fp_rate: float
    fn_rate: float
    accuracy: float
    cycles_mean: float  # NaN for a host-only method
    cycles_min: int | None
    cycles_max: int | None
    cycle_samples: int
    code_bytes: int | None
    table_bytes: int | None
    host_us: float
    host_only: bool
    hardware: bool  # needs the VIC-II's collision hardware (not on the NES, not past 8 sprites)
    pareto: bool  # on the (cycles, accuracy) Pareto front of its scope, all methods
    pareto_software: bool  # on the front of the software methods (the hardware latch left out)


def _rows_for_scope(scope: str, cases: int, colliding: int, counts: dict[str, Confusion], table: AccuracyTable,
                    costs: dict[str, MethodCost]) -> list[FigureRow]:
    rows = []
    for m in table.methods:
        c = counts[m.key]
        cost = costs.get(m.key)
        stats = cost.cycles_for(None if scope == ALL else scope) if cost else None
        has_cycles = stats is not None and stats.samples > 0 and not m.host_only
        rows.append(FigureRow(
            scope=scope, method=m.key, label=m.label, cases=cases, colliding=colliding,
            tp=c.tp, fp=c.fp, tn=c.tn, fn=c.fn, fp_rate=c.fp_rate, fn_rate=c.fn_rate, accuracy=c.accuracy,
            cycles_mean=stats.mean if has_cycles else math.nan,
            cycles_min=stats.min if has_cycles else None, cycles_max=stats.max if has_cycles else None,
            cycle_samples=stats.samples if has_cycles else 0,
            code_bytes=cost.code_bytes if cost else None, table_bytes=cost.table_bytes if cost else None,
            host_us=cost.host_us if cost else math.nan, host_only=m.host_only, hardware=m.hardware, pareto=False,
            pareto_software=False))
    front = pareto_front([(r.cycles_mean, r.accuracy) for r in rows])
    software = pareto_front([(math.nan, 0.0) if r.hardware else (r.cycles_mean, r.accuracy) for r in rows])
    return [FigureRow(**{**asdict(r), "pareto": on, "pareto_software": soft})
            for r, on, soft in zip(rows, front, software)]


def figure_rows(table: AccuracyTable, costs: dict[str, MethodCost]) -> list[FigureRow]:
    """ALL first, then each pair in corpus order; methods in the order of table.methods."""
    overall = {m.key: table.overall(m.key) for m in table.methods}
    rows = _rows_for_scope(ALL, table.cases, sum(p.colliding for p in table.pairs), overall, table, costs)
    for p in table.pairs:
        rows += _rows_for_scope(p.pair, p.cases, p.colliding, p.counts, table, costs)
    return rows


# ---- CSV ------------------------------------------------------------------------------------------

COLUMNS = [f.name for f in fields(FigureRow)]


def _cell(value: object) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return repr(value)  # shortest exact round-trip form
    return str(value)


def rows_to_csv(rows: list[FigureRow]) -> str:
    return csv_text(COLUMNS, ([_cell(getattr(r, c)) for c in COLUMNS] for r in rows))


_INT_OR_NONE = {"cycles_min", "cycles_max", "code_bytes", "table_bytes"}
_INT = {"cases", "colliding", "cycle_samples"}
_BOOL = {"host_only", "hardware", "pareto", "pareto_software"}
_STR = {"scope", "method", "label"}


def _parse(column: str, text: str) -> object:
    if column in _STR:
        return text
    if column in _BOOL:
        return text == "1"
    if column in _INT:
        return int(text)
    if column in _INT_OR_NONE:
        return int(text) if text else None
    return float(text) if text else math.nan


def rows_from_csv(text: str) -> list[FigureRow]:
    return [FigureRow(**{c: _parse(c, row[c]) for c in COLUMNS}) for row in csv_records(text, COLUMNS)]


# ---- Markdown -------------------------------------------------------------------------------------

def _pct(value: float, digits: int = 1) -> str:
    return "n/a" if math.isnan(value) else f"{100 * value:.{digits}f}%"


def _cycles(r: FigureRow) -> str:
    if r.host_only:
        return "host only (no 6502 routine)"
    if math.isnan(r.cycles_mean):
        return "not measured"
    return f"{r.cycles_mean:.1f} ({r.cycles_min}-{r.cycles_max})"


def _bytes(r: FigureRow) -> str:
    if r.code_bytes is None:
        return "-"
    return f"{r.code_bytes} + {r.table_bytes or 0}"


def markdown_table(rows: list[FigureRow], scope: str = ALL) -> str:
    """One scope's rows as a Markdown table, cheapest first, host-only methods last."""
    chosen = [r for r in rows if r.scope == scope]
    chosen.sort(key=lambda r: (r.host_only or math.isnan(r.cycles_mean), r.cycles_mean if not math.isnan(r.cycles_mean) else 0))
    lines = ["| method | cycles per test, mean (min-max) | code + table bytes | FP rate | FN rate | accuracy | host us "
             "| Pareto (all / software) |", "|---|---|---|---|---|---|---|---|"]
    for r in chosen:
        host = "n/a" if math.isnan(r.host_us) else f"{r.host_us:.1f}"
        lines.append(f"| {r.label} | {_cycles(r)} | {_bytes(r)} | {_pct(r.fp_rate)} | {_pct(r.fn_rate)} | "
                     f"{_pct(r.accuracy, 2)} | {host} | {'yes' if r.pareto else 'no'} / "
                     f"{'yes' if r.pareto_software else ('-' if r.hardware else 'no')} |")
    return "\n".join(lines) + "\n"


def markdown_pairs(rows: list[FigureRow]) -> str:
    """Accuracy of every method on every pair (rows) — the per-pair figures at a glance."""
    methods = list(dict.fromkeys(r.method for r in rows))
    labels = {r.method: r.label for r in rows}
    scopes = [s for s in dict.fromkeys(r.scope for r in rows) if s != ALL]
    by = {(r.scope, r.method): r for r in rows}
    head = "| pair | cases | colliding | " + " | ".join(labels[m] for m in methods) + " |"
    lines = [head, "|" + "---|" * (3 + len(methods))]
    for s in scopes:
        first = by[(s, methods[0])]
        cells = []
        for m in methods:
            r = by[(s, m)]
            cells.append(f"{_pct(r.accuracy)}" + (" *" if r.pareto_software else ""))
        lines.append(f"| {s} | {first.cases} | {first.colliding} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
