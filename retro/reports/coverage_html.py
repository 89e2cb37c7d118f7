"""`retro check --html DIR`: the coverage as a folder of HTML pages, as coverage.py's `htmlcov` is
(docs/coverage.md): `index.html` lists the routines with their instruction and branch coverage, and
each routine has a page of its listing: hits and cycles as a heat map, both branch directions with
their counts, the worst case's path marked, the instructions no case ran and the branch directions
never taken in red. Every page stands alone: inline CSS and script, no network, no other file.

Keys on a routine's page: `n` / `p` jump to the next / previous line that needs a look (never run, or
a branch that went one way), `m` shows only those lines (also `#missed` in the address)."""

from __future__ import annotations

import html
import math
import re
from collections.abc import Callable
from pathlib import Path

from retro.reports.annotated import Annotated, Gap, Row, percent

INDEX = "index.html"
# coverage.py's colours for run, missed and partial lines; the heat ramps from white to orange
RUN_COLOUR = "#ddffdd"
MISSED_COLOUR = "#ffdddd"
PARTIAL_COLOUR = "#ffffaa"
WORST_COLOUR = "#7a3df0"  # the worst case's path: a bar at the left of its rows
HEAT_RGB = (255, 140, 0)

_STYLE = f"""
body {{ font-family: sans-serif; margin: 1em 2em; color: #222; }}
h1 {{ font-size: 1.4em; }}
table {{ border-collapse: collapse; }}
td, th {{ padding: 1px 8px; text-align: right; white-space: pre; }}
th {{ border-bottom: 1px solid #888; }}
td.code, th.code, td.src, th.src, td.line, th.line {{ text-align: left; font-family: monospace; }}
td.addr, td.bytes {{ font-family: monospace; text-align: left; }}
tr.run {{ background: {RUN_COLOUR}; }}
tr.missed {{ background: {MISSED_COLOUR}; }}
tr.partial {{ background: {PARTIAL_COLOUR}; }}
tr.worst td.mark {{ background: {WORST_COLOUR}; }}
td.mark {{ width: 6px; padding: 0; }}
tr.label td {{ background: #fff; text-align: left; font-family: monospace; font-weight: bold; padding-top: 4px; }}
tr.gap td {{ background: #f4f4f4; color: #777; text-align: left; font-style: italic; }}
span.never {{ color: #c00000; font-weight: bold; }}
body.missed-only tr.run, body.missed-only tr.label {{ display: none; }}
.legend span {{ display: inline-block; padding: 1px 8px; margin-right: 6px; }}
p.summary {{ font-size: 1.05em; }}
"""

_SCRIPT = """
(function () {
  var rows = Array.prototype.slice.call(document.querySelectorAll('tr.missed, tr.partial'));
  var at = -1;
  function show(i) {
    if (!rows.length) return;
    at = (i + rows.length) % rows.length;
    rows[at].scrollIntoView({block: 'center'});
  }
  function missedOnly(on) { document.body.classList.toggle('missed-only', on); }
  document.addEventListener('keydown', function (e) {
    if (e.key === 'n') show(at + 1);
    else if (e.key === 'p') show(at - 1);
    else if (e.key === 'm') missedOnly(!document.body.classList.contains('missed-only'));
  });
  missedOnly(location.hash === '#missed');
  // where each line is drawn (page coordinates), for tools that check the page as it is seen
  document.querySelectorAll('tr[id]').forEach(function (tr) {
    var box = tr.getBoundingClientRect();
    tr.setAttribute('data-top', Math.round(box.top + window.scrollY));
    tr.setAttribute('data-height', Math.round(box.height));
  });
  document.body.setAttribute('data-ready', 'yes');
})();
"""


def _page(title: str, body: str) -> str:
    return (f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            f"<title>{html.escape(title)}</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n{body}\n"
            f"<script>{_SCRIPT}</script>\n</body>\n</html>\n")


def _heat(value: int | None, top: int) -> str:
    """A background from white (0) to orange (the most), on a log scale: counts span orders of magnitude."""
    if not value or not top:
        return ""
    share = math.log1p(value) / math.log1p(top)
    r, g, b = (round(255 - (255 - c) * share) for c in HEAT_RGB)
    return f' style="background: rgb({r}, {g}, {b})"'


def _count(value: int | None, row: Row, arrow: str, never: str) -> str:
    if value is None:
        return ""
    if not row.run:
        return "-"
    if value == 0:
        return f'<span class="never" title="{never}">{arrow} 0</span>'
    return f"{arrow} {value:,}"


def _row_class(row: Row) -> str:
    kind = "missed" if not row.run else "partial" if row.partial else "run"
    return kind + (" worst" if row.on_worst_path else "")


def _source_cells(row: Row, source_text: Callable[[str], list[str] | None]) -> str:
    """The line (file:line, the full path in its tooltip) and its text when the file can be read."""
    if row.source is None:
        return '<td class="line"></td><td class="src"></td>'
    where = f"{Path(row.source.file).name}:{row.source.line}"
    lines = source_text(row.source.file)
    text = lines[row.source.line - 1].rstrip().expandtabs() if lines and 0 < row.source.line <= len(lines) else ""
    return (f'<td class="line" title="{html.escape(row.source.file)}">{html.escape(where)}</td>'
            f'<td class="src">{html.escape(text)}</td>')


def routine_page(annotated: Annotated, source_text: Callable[[str], list[str] | None] = lambda file: None) -> str:
    """One routine's page: its summary, the worst case, a legend and a table with one row per
    instruction (labels and gaps between them), heat-coloured by hits and cycles."""
    code = annotated.code
    has_source = any(row.source is not None for row in annotated.rows)
    head = ("<tr><th></th><th>address</th><th>bytes</th><th class=\"code\">instruction</th><th>hits</th>"
            "<th title=\"taken\">taken</th><th title=\"not taken\">not taken</th><th>min cycles</th><th>max cycles</th>"
            + ("<th class=\"line\">line</th><th class=\"src\">source</th>" if has_source else "") + "</tr>")
    worst = (f"<p>Worst case: {annotated.worst_cycles:,} cycles over {annotated.worst_length:,} instructions; its path "
             f"is marked by the bar at the left.</p>" if annotated.worst_cycles is not None else "")
    legend = (f'<p class="legend"><span style="background: {RUN_COLOUR}">run</span>'
              f'<span style="background: {MISSED_COLOUR}">never run</span>'
              f'<span style="background: {PARTIAL_COLOUR}">branch went one way only</span>'
              f'<span style="background: {WORST_COLOUR}; color: #fff">worst case path</span>'
              f"keys: n / p next / previous line to look at, m only those lines</p>")
    origin = f" ({html.escape(code.program_file)})" if code.program_file else ""
    content = (f'<p><a href="{INDEX}">all routines</a></p>\n<h1>{html.escape(code.name)}</h1>\n'
               f"<p>entry ${code.entry:04X}{origin}</p>\n<p class=\"summary\">{html.escape(annotated.summary())}</p>\n"
               f"{worst}\n{legend}\n<table>\n{head}\n" + "\n".join(_table_rows(annotated, has_source, source_text))
               + "\n</table>")
    return _page(f"{code.name}: coverage", content)


def _table_rows(annotated: Annotated, has_source: bool, source_text: Callable[[str], list[str] | None]) -> list[str]:
    """The table's rows in address order: a gap's one line, an instruction's labels and its row."""
    columns = 11 if has_source else 9
    top_hits = max((row.hits for row in annotated.rows), default=0)
    top_cycles = max((row.cycles_max or 0 for row in annotated.rows), default=0)
    body = []
    for piece in annotated.pieces():
        if isinstance(piece, Gap):
            text = (f"${piece.start:04X}-${piece.end - 1:04X}: {piece.end - piece.start:,} byte(s) no path from the entry runs"
                    if piece.end > piece.start else "the next instruction overlaps this one")
            body.append(f'<tr class="gap"><td colspan="{columns}">{html.escape(text)}</td></tr>')
            continue
        body += [f'<tr class="label"><td></td><td colspan="{columns - 1}">{html.escape(label)}:</td></tr>'
                 for label in piece.labels]
        cells = _instruction_cells(piece, top_hits, top_cycles)
        if has_source:
            cells.append(_source_cells(piece, source_text))
        body.append(f'<tr id="a{piece.address:04X}" class="{_row_class(piece)}">{"".join(cells)}</tr>')
    return body


def _instruction_cells(row: Row, top_hits: int, top_cycles: int) -> list[str]:
    """An instruction's cells: worst-path mark, address, bytes, text, hits, branch directions, cycles."""
    instruction = row.instruction
    data = " ".join(f"{b:02X}" for b in instruction.data) if instruction else "??"
    text = instruction.text if instruction else "(outside the program's bytes)"
    hits = f"{row.hits:,}" if row.run else '<span class="never">never run</span>'
    return [f'<td class="mark" title="{"on the worst case&#39;s path" if row.on_worst_path else ""}"></td>',
            f'<td class="addr">${row.address:04X}</td>', f'<td class="bytes">{data}</td>',
            f'<td class="code">{html.escape(text)}</td>', f'<td class="hits"{_heat(row.hits, top_hits)}>{hits}</td>',
            f'<td class="taken">{_count(row.taken, row, "&#8594;", "never taken")}</td>',
            f'<td class="nottaken">{_count(row.not_taken, row, "&#8595;", "never fell through")}</td>',
            f'<td class="cmin">{"" if row.cycles_min is None else row.cycles_min}</td>',
            f'<td class="cmax"{_heat(row.cycles_max, top_cycles)}>{"" if row.cycles_max is None else row.cycles_max}</td>']


def page_names(routines: list[Annotated]) -> list[str]:
    """One file name per routine, unique: its name with anything but letters, digits, `-`, `_` made `_`."""
    names, used = [], set()
    for annotated in routines:
        stem = re.sub(r"[^A-Za-z0-9_-]", "_", annotated.code.name) or "routine"
        name, n = f"{stem}.html", 2
        while name in used or name == INDEX:
            name, n = f"{stem}_{n}.html", n + 1
        used.add(name)
        names.append(name)
    return names


def index_page(routines: list[Annotated], names: list[str]) -> str:
    rows = []
    for annotated, name in zip(routines, names):
        rows.append(f'<tr><td class="code"><a href="{name}">{html.escape(annotated.code.name)}</a></td>'
                    f"<td>{annotated.instructions_run} / {annotated.instructions}</td>"
                    f"<td>{percent(annotated.instructions_run, annotated.instructions)}</td>"
                    f"<td>{annotated.directions_run} / {annotated.branch_directions}</td>"
                    f"<td>{percent(annotated.directions_run, annotated.branch_directions)}</td>"
                    f"<td>{'' if annotated.worst_cycles is None else f'{annotated.worst_cycles:,}'}</td></tr>")
    content = ("<h1>Code coverage</h1>\n<table>\n<tr><th class=\"code\">routine</th><th>instructions run</th><th></th>"
               "<th>branch directions</th><th></th><th>worst case cycles</th></tr>\n" + "\n".join(rows) + "\n</table>")
    return _page("Code coverage", content)


def html_pages(routines: list[Annotated], source_text: Callable[[str], list[str] | None] = lambda file: None) -> dict[str, str]:
    """File name -> page: `index.html` and one page per routine."""
    names = page_names(routines)
    pages = {INDEX: index_page(routines, names)}
    pages.update({name: routine_page(annotated, source_text) for annotated, name in zip(routines, names)})
    return pages
