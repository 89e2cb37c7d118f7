"""`retro check --listing FILE`: the annotated listing, one line per instruction (docs/coverage.md).

    > $C004   F0 09     BEQ $C00F                3        1         2     2     3  sumto.s:6

Columns: the worst case's path (`>`), address, bytes, instruction, hits, for a conditional branch
how often it was taken and not taken, the fewest and most cycles one run of it took (page and branch
penalties included, stolen cycles not), and the source line when the program's line information is
known. The user's labels stand on their own line above their instruction. An instruction no case ran
shows `#####` for its hits (gcov's mark), a branch direction never taken `0!`."""

from __future__ import annotations

from pathlib import Path

from retro.reports.annotated import Annotated, Gap, Row

NEVER_RUN = "#####"
NEVER_TAKEN = "0!"
WORST_MARK = ">"
LABEL_COLUMN = 20  # where the instruction column starts
HEADER = (f"  {'address':<7} {'bytes':<9} {'instruction':<16} {'hits':>9} {'taken':>8} {'not taken':>9} "
          f"{'min':>5} {'max':>5}  source")


def _count(value: int | None, ran: bool) -> str:
    if value is None:
        return ""
    if not ran:
        return "-"
    return NEVER_TAKEN if value == 0 else f"{value:,}"


def _source(row: Row) -> str:
    return f"{Path(row.source.file).name}:{row.source.line}" if row.source is not None else ""


def row_line(row: Row) -> str:
    instruction = row.instruction
    data = " ".join(f"{b:02X}" for b in instruction.data) if instruction else "??"
    text = instruction.text if instruction else "(outside the program's bytes)"
    hits = f"{row.hits:,}" if row.run else NEVER_RUN
    cycles = ("" if row.cycles_min is None else f"{row.cycles_min:>5}", "" if row.cycles_max is None else f"{row.cycles_max:>5}")
    line = (f"{WORST_MARK if row.on_worst_path else ' '} {'$%04X' % row.address:<7} {data:<9} {text:<16} {hits:>9} "
            f"{_count(row.taken, row.run):>8} {_count(row.not_taken, row.run):>9} {cycles[0]:>5} {cycles[1]:>5}  {_source(row)}")
    return line.rstrip()


def gap_line(gap: Gap) -> str:
    if gap.end < gap.start:
        return f"  (the next instruction overlaps this one: it starts ${gap.start - gap.end:X} byte(s) earlier)"
    size = gap.end - gap.start
    return f"  ${gap.start:04X}-${gap.end - 1:04X}: {size:,} byte{'s' if size != 1 else ''} no path from the entry runs"


def listing_lines(annotated: Annotated) -> list[str]:
    code = annotated.code
    lines = [f"{code.name}: entry ${code.entry:04X}" + (f", init ${code.init:04X}" if code.init is not None else "")
             + (f" ({code.program_file})" if code.program_file else ""),
             f"  {annotated.summary()}"]
    if annotated.worst_cycles is not None:
        lines.append(f"  worst case: {annotated.worst_cycles:,} cycles over {annotated.worst_length:,} instructions "
                     f"(marked {WORST_MARK})")
    lines += [f"  {NEVER_RUN}: never run; {NEVER_TAKEN}: a branch direction never taken", "", HEADER]
    for piece in annotated.pieces():
        if isinstance(piece, Gap):
            lines.append(gap_line(piece))
            continue
        lines += [f"{'':{LABEL_COLUMN}}{label}:" for label in piece.labels]
        lines.append(row_line(piece))
    return lines


def listing_text(routines: list[Annotated]) -> str:
    """Every routine's listing, a blank line between them."""
    return "\n\n".join("\n".join(listing_lines(a)) for a in routines) + "\n"
