"""Expected rows: inputs written by hand with the outputs (and cycles) they must give.

A spec's `rows` is an array of tables, written either way (TOML reads both as the same list):

    rows = [
      { ax = 10, bx = "$14", hit = 1 },
      { ax = 10, bx = 18, hit = 0, cycles = 24 },
    ]

    [[rows]]
    ax = 10
    bx = "$14"
    hit = 1

A row names every input and the outputs it states (an output it leaves out is not compared),
with optional `cycles` (exact), `max_cycles` (a per-row budget) and `note` (shown when the row
fails). A name that is both an input and an output is written `in.NAME` / `out.NAME` (TOML's dotted
keys: `{ in.a = 3, out.a = 4 }`), as is an input or output named `cycles`, `max_cycles` or `note`
(a bare key of those names is the row's own); an input or output named `in` or `out` is written bare,
unless its value is a table.
Numbers take every notation retro reads (`$C0`, `0xc0`, `%1010`, `192`, TOML's `0xC0`, `0b1010`);
a flag takes 0/1 or true/false; a table a list of bytes or a string of hex bytes.

This module only reads rows into plain data; retro.analysis.row_check runs them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from retro.fields import Fields, describe

if TYPE_CHECKING:
    from retro.routines.spec import Port

ROW_KEYS = ("cycles", "max_cycles", "note", "in", "out")  # a row's own keys, besides input and output names
MAX_ROW_CYCLES = 1 << 40
NOTE_CHARACTERS = 200


@dataclass(frozen=True)
class Row:
    """One expected row: the case (inputs in the spec's order) and what it must give."""

    index: int  # its position in `rows`, from 0, as errors name it (`rows[2]`)
    case: tuple  # an int per number or flag, a tuple of bytes per table
    expected: tuple  # per output, in the spec's order: the stated value, or None where the row says nothing
    cycles: int | None = None  # exact cycles of the call
    max_cycles: int | None = None
    note: str = ""

    @property
    def key(self) -> str:
        return f"rows[{self.index}]"

    @property
    def label(self) -> str:
        return f"{self.key} ({self.note})" if self.note else self.key


def parse_rows(r: Fields, value, inputs: tuple[Port, ...], outputs: tuple[Port, ...]) -> tuple[Row, ...]:
    """The spec's `rows`; each bad row is one error naming the file, `rows[i]` and the key."""
    if isinstance(value, dict):  # `[rows]` written for `[[rows]]`
        raise r.error("rows", "expected an array of rows: [[rows]] tables, or rows = [{ ... }, { ... }]")
    tables = r.array_of_tables(value, "rows")
    if not tables:
        raise r.error("rows", "the list of rows is empty")
    return tuple(_row(r, i, doc, inputs, outputs) for i, doc in enumerate(tables))


def _row(r: Fields, index: int, doc: dict, inputs: tuple[Port, ...], outputs: tuple[Port, ...]) -> Row:
    key = f"rows[{index}]"
    given_in, given_out = _given(r, key, doc, inputs, outputs)
    missing = [p.name for p in inputs if p.name not in given_in]
    if missing:
        raise r.error(f"{key}.{missing[0]}", f"missing: a row gives every input ({', '.join(p.name for p in inputs)})")
    case = tuple(port_value(r, port, *given_in[port.name]) for port in inputs)  # (value, key as written)
    expected = tuple(port_value(r, port, *given_out[port.name]) if port.name in given_out else None for port in outputs)
    cycles = r.integer(doc["cycles"], f"{key}.cycles", 1, MAX_ROW_CYCLES) if "cycles" in doc else None
    max_cycles = r.integer(doc["max_cycles"], f"{key}.max_cycles", 1, MAX_ROW_CYCLES) if "max_cycles" in doc else None
    note = doc.get("note", "")
    if not isinstance(note, str) or len(note) > NOTE_CHARACTERS or "\n" in note:
        raise r.error(f"{key}.note", f"expected one line of at most {NOTE_CHARACTERS} characters, got {describe(note)}")
    if all(value is None for value in expected) and cycles is None and max_cycles is None:
        raise r.error(key, f"states no output, cycles or max_cycles: nothing to check (outputs: "
                           f"{', '.join(p.name for p in outputs)})")
    return Row(index, case, expected, cycles, max_cycles, note.strip())


def _given(r: Fields, key: str, doc: dict, inputs: tuple[Port, ...],
           outputs: tuple[Port, ...]) -> tuple[dict[str, tuple], dict[str, tuple]]:
    """A row's inputs and outputs, name -> (value, its key as written: rows[i].in.a or rows[i].a)."""
    input_names = {p.name for p in inputs}
    output_names = {p.name for p in outputs}
    given: dict[str, dict[str, tuple]] = {"in": {}, "out": {}}

    def put(side: str, name: str, value, where: str) -> None:
        if name in given[side]:
            raise r.error(where, "given twice (bare and under in/out)")
        given[side][name] = (value, where)

    for name, item in doc.items():
        if name in ("in", "out") and (isinstance(item, dict) or name not in input_names | output_names):
            names, what = (input_names, "input") if name == "in" else (output_names, "output")
            for inner, inner_value in r.table(item, f"{key}.{name}").items():
                if inner not in names:
                    raise r.error(f"{key}.{name}.{inner}",
                                  f"no {what} of that name ({what}s: {', '.join(sorted(names))})")
                put(name, inner, inner_value, f"{key}.{name}.{inner}")
        elif name in ROW_KEYS and name not in ("in", "out"):
            continue
        elif name in input_names and name in output_names:
            raise r.error(f"{key}.{name}", f"{name!r} is both an input and an output: write in.{name} or out.{name}")
        elif name in input_names or name in output_names:
            put("in" if name in input_names else "out", name, item, f"{key}.{name}")
        else:
            raise r.error(f"{key}.{name}", f"neither an input nor an output (inputs: "
                                           f"{', '.join(p.name for p in inputs)}; outputs: "
                                           f"{', '.join(p.name for p in outputs)}; a row's own keys: {', '.join(ROW_KEYS)})")
    return given["in"], given["out"]


def port_value(r: Fields, port: Port, value, key: str):
    """A value written for an input or output: a number that fits the port, a flag, or a table's bytes."""
    if port.table:
        size = len(port.places)
        if isinstance(value, str):
            from retro.routines.spec import _byte_list  # the spec's one reader of hex-byte strings

            data = _byte_list(r, value, key)
        else:
            data = tuple(r.byte_list(value, key))
        if len(data) != size:
            raise r.error(key, f"expected {size} bytes ({port.describe()}), got {len(data)}")
        return tuple(data)
    if port.flag and isinstance(value, bool):
        return int(value)
    return r.integer(value, key, 0, (1 << port.bits) - 1)


def misplaced_rows(r: Fields, doc: dict) -> None:
    """`rows = [...]` written below a `[table]` header belongs to that table in TOML: say so, in place
    of the puzzling error the table would give (`outputs.rows.at: ...`)."""
    for section, table in doc.items():
        rows = table.get("rows") if isinstance(table, dict) else None
        if isinstance(rows, list) and rows and all(isinstance(item, dict) for item in rows):
            raise r.error(f"{section}.rows", f"rows written below [{section}] belong to that table in TOML: put "
                                             "rows = [...] above the first [table] header, or write [[rows]] tables")
