"""`retro check --lcov FILE`: the coverage as an LCOV tracefile, the format `geninfo` writes and
`genhtml`, `lcov` and most CI coverage services read (geninfo(1), LCOV 1.16, "TRACEFILE FORMAT"):
per source file `TN:` `SF:` `FN:` `FNDA:` `FNF:` `FNH:` `BRDA:` `BRF:` `BRH:` `DA:` `LF:` `LH:`
`end_of_record`.

Mapping (docs/coverage.md):
- Where the program has line information (an ld65 `--dbgfile` given as `[program] symbols`, or an
  ACME `--report` given as `[program] listing`), each instruction counts on its source line: a line's
  `DA` count is the most runs of any instruction on it (a macro's call line ran when its first
  instruction did; an instruction inside it that never ran shows in the listing and, for branches,
  in its `BRDA` lines).
- Elsewhere (Ophis sources, binaries without such a file, addresses the line information does not
  name), the instructions count in a pseudo file named after the program with `.addresses` added,
  whose line N stands for address N (`$C000` is line 49152); no such file exists, so genhtml needs
  `--no-source` (or `--ignore-errors source`) for it.
- Each conditional branch is two `BRDA` entries on its line: branch 0 taken, branch 1 not taken
  (`-` when the branch never ran); the block number tells apart two branches on one line.
- The routine's entry (and init) are the functions: `FN` at their line, `FNDA` how often they ran.
- `TN` and the function names are the routine's name with every character other than a letter,
  digit or `_` made `_` (the test names geninfo accepts; a comma would end genhtml's function name),
  the init `NAME_init`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from retro.reports.annotated import Annotated, Row

ADDRESSES_SUFFIX = ".addresses"


@dataclass
class _FileRecord:
    functions: list[tuple[int, str, int]] = field(default_factory=list)  # (line, name, hits)
    lines: dict[int, int] = field(default_factory=dict)  # line -> count
    branches: list[tuple[int, int, Row]] = field(default_factory=list)  # (line, block, branch row)


def test_name(name: str) -> str:
    return re.sub(r"\W", "_", name, flags=re.ASCII) or "_"


def pseudo_file(annotated: Annotated) -> str:
    """`/path/game.prg.addresses`: the file whose line N stands for address N (the routine's name
    when the program has no file)."""
    code = annotated.code
    return (str(Path(code.program_file).resolve()) if code.program_file else code.name) + ADDRESSES_SUFFIX


def _place(annotated: Annotated, row: Row) -> tuple[str, int]:
    if row.source is not None:
        return row.source.file, row.source.line
    return pseudo_file(annotated), row.address


def _records(annotated: Annotated) -> dict[str, _FileRecord]:
    records: dict[str, _FileRecord] = {}
    blocks: dict[tuple[str, int], int] = {}
    for row in annotated.rows:
        file, line = _place(annotated, row)
        record = records.setdefault(file, _FileRecord())
        record.lines[line] = max(record.lines.get(line, 0), row.hits)
        if row.is_branch:
            block = blocks.get((file, line), 0)
            blocks[(file, line)] = block + 1
            record.branches.append((line, block, row))
    code = annotated.code
    by_address = {row.address: row for row in annotated.rows}
    for address, name in ((code.entry, test_name(code.name)), (code.init, test_name(code.name) + "_init")):
        if address is None or address not in by_address:
            continue
        row = by_address[address]
        file, line = _place(annotated, row)
        records[file].functions.append((line, name, row.hits))
    return records


def _branch_count(value: int | None, row: Row) -> str:
    return "-" if not row.run else str(value)


def lcov_records(annotated: Annotated) -> list[str]:
    lines = []
    for file, record in sorted(_records(annotated).items()):
        lines += [f"TN:{test_name(annotated.code.name)}", f"SF:{file}"]
        lines += [f"FN:{line},{name}" for line, name, _ in record.functions]
        lines += [f"FNDA:{hits},{name}" for _, name, hits in record.functions]
        lines += [f"FNF:{len(record.functions)}", f"FNH:{sum(hits > 0 for *_, hits in record.functions)}"]
        entries = []
        for line, block, row in sorted(record.branches, key=lambda b: (b[0], b[1])):
            entries += [(line, block, 0, _branch_count(row.taken, row)), (line, block, 1, _branch_count(row.not_taken, row))]
        lines += [f"BRDA:{line},{block},{branch},{taken}" for line, block, branch, taken in entries]
        lines += [f"BRF:{len(entries)}", f"BRH:{sum(taken not in ('-', '0') for *_, taken in entries)}"]
        lines += [f"DA:{line},{count}" for line, count in sorted(record.lines.items())]
        lines += [f"LF:{len(record.lines)}", f"LH:{sum(count > 0 for count in record.lines.values())}", "end_of_record"]
    return lines


def lcov_text(routines: list[Annotated]) -> str:
    return "".join(line + "\n" for annotated in routines for line in lcov_records(annotated))
