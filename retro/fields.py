"""Field validation for the TOML files users write (scenes, routine specs, method files).

One `Fields` per document names its file; every error it raises is one line,
`"{source}: {field}: {message}"`, so a mistake reads the same in every kind of file:

    scene.toml: sprite[0].flip: unknown key (known: behind, color, ...)
    scene.toml: ppu.ctrl: expected an integer, got 1.5
    spec.toml: cycles.max: 0 is out of range 1..1099511627776

The rules, the same for every kind of file:
- a table with `known` keys rejects any other key, listing the known ones;
- an integer is a TOML integer or a string in a notation `parse_int` reads ($C000, 0xc000, %1010,
  49152); booleans and floats are never integers (TOML's `true` is not 1, `1.0` is not 1);
- a range is inclusive and printed as `lo..hi`;
- a missing required key is named with its table (`oam[0].y: missing`);
- a file is named relative to the folder of the document that names it.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from pathlib import Path

from retro.errors import InputError
from retro.fileio import exists, is_dir, is_file, read_bytes
from retro.numbers import MAX_DIGITS, parse_int

SHOWN_CHARACTERS = 40  # of a string quoted in an error: enough to recognise it, short enough for one line
SHOWN_PATH = 200  # of a path in an error


def describe(value) -> str:
    """A value as an error shows it, in TOML's words: `true`, `1.5`, `'abc'`, `an array`, `a table`."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return repr(value) if len(value) <= SHOWN_CHARACTERS else f"{value[:SHOWN_CHARACTERS]!r}..."
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


def join(prefix: str, key) -> str:
    """`prefix.key`, or `key` at the top of the document."""
    return f"{prefix}.{key}" if prefix else str(key)


class Fields:
    """Checks the values of one document; every error names `source` and the field.

    `folder` is where file names in the document are relative to (default: the source's folder);
    `number_characters` is the longest string read as a number.
    """

    def __init__(self, source: str, folder: str | Path | None = None, number_characters: int = MAX_DIGITS) -> None:
        self.source = str(source)
        self.folder = Path(folder) if folder is not None else Path(self.source).parent
        self.number_characters = number_characters

    def error(self, field: str, message: str) -> InputError:
        return InputError(f"{self.source}: {field}: {message}" if field else f"{self.source}: {message}")

    # ---- tables -----------------------------------------------------------------------------------

    def table(self, value, field: str, known: Collection[str] | None = None) -> dict:
        """`value` as a table; with `known`, any other key is an error."""
        if not isinstance(value, dict):
            raise self.error(field, f"expected a table, got {describe(value)}")
        if known is not None:
            self.known(value, field, known)
        return value

    def known(self, table: Mapping, field: str, known: Collection[str]) -> None:
        unknown = sorted(str(key) for key in table if key not in known)
        if unknown:
            raise self.error(join(field, unknown[0]), f"unknown key (known: {', '.join(sorted(known))})")

    def array_of_tables(self, value, field: str, known: Collection[str] | None = None) -> list[dict]:
        """`[[field]]`: a list of tables, each checked as `field[i]`."""
        if not isinstance(value, list):
            raise self.error(field, f"expected an array of tables ([[{field}]]), got {describe(value)}")
        return [self.table(item, f"{field}[{i}]", known) for i, item in enumerate(value)]

    def array(self, value, field: str, items: str) -> list:
        """A list; `items` says what it holds, for the error (e.g. "{col, row, tile} tables")."""
        if not isinstance(value, list):
            raise self.error(field, f"expected an array of {items}, got {describe(value)}")
        return value

    def required(self, table: Mapping, key: str, field: str = "", hint: str = ""):
        """`table[key]`; absent, an error naming `field.key` (the hint says what to give)."""
        if key not in table:
            raise self.error(join(field, key), "missing" + (f": {hint}" if hint else ""))
        return table[key]

    def exactly_one(self, table: Mapping, keys: Iterable[str], field: str) -> str:
        """The one of `keys` that `table` gives; none or several is an error."""
        keys = tuple(keys)
        given = [key for key in keys if key in table]
        if len(given) != 1:
            raise self.error(field, f"give exactly one of {', '.join(keys)} (got {', '.join(given) or 'none'})")
        return given[0]

    # ---- scalars ----------------------------------------------------------------------------------

    def integer(self, value, field: str, lo: int | None = None, hi: int | None = None, *,
                strings: bool = True) -> int:
        """A whole number in lo..hi; with `strings` (the default) also one written as text."""
        if isinstance(value, bool) or not isinstance(value, (int, str)) or (isinstance(value, str) and not strings):
            raise self.error(field, f"expected an integer, got {describe(value)}")
        if isinstance(value, str) and len(value) > self.number_characters:
            raise self.error(field, f"not a number: {value[:20]!r}... ({len(value)} characters)")
        return parse_int(value, field=f"{self.source}: {field}", lo=lo, hi=hi)

    def byte(self, value, field: str) -> int:
        return self.integer(value, field, 0, 0xFF)

    def integers(self, value, field: str, count: int, lo: int, hi: int, *, strings: bool = True) -> tuple[int, ...]:
        """`count` integers in lo..hi: a list of them, or one integer that stands for all."""
        if isinstance(value, list):
            if len(value) != count:
                raise self.error(field, f"expected an integer or a list of {count}, got {len(value)} items")
            return tuple(self.integer(v, f"{field}[{i}]", lo, hi, strings=strings) for i, v in enumerate(value))
        return (self.integer(value, field, lo, hi, strings=strings),) * count

    def byte_list(self, value, field: str, length: int | None = None, most: int | None = None) -> list[int]:
        """A list of bytes: exactly `length` of them, or at most `most`."""
        wanted = f"a list of {length} bytes" if length is not None else "a list of bytes"
        if not isinstance(value, list):
            raise self.error(field, f"expected {wanted}, got {describe(value)}")
        if length is not None and len(value) != length:
            raise self.error(field, f"expected {wanted}, got {len(value)}")
        if most is not None and len(value) > most:
            raise self.error(field, f"more than {most} bytes")
        return [self.byte(v, f"{field}[{i}]") for i, v in enumerate(value)]

    def flag(self, value, field: str) -> bool:
        if not isinstance(value, bool):
            raise self.error(field, f"expected true or false, got {describe(value)}")
        return value

    def string(self, value, field: str, most: int | None = None) -> str:
        """A string with something in it besides spaces (at most `most` characters)."""
        if not isinstance(value, str) or not value.strip():
            raise self.error(field, f"expected a non-empty string, got {describe(value)}")
        if most is not None and len(value) > most:
            raise self.error(field, f"longer than {most} characters")
        return value

    def choice(self, value, field: str, choices: Iterable[str], *, labels: Mapping[str, str] | None = None,
               fold_case: bool = False) -> str:
        """One of `choices` (a mapping's keys); `labels` shows a choice in the error with what it means
        (`'pal' (6569)`); with `fold_case` the text may be in any case and comes back in lower case."""
        choices = tuple(choices)
        text = value.lower() if fold_case and isinstance(value, str) else value
        if not isinstance(text, str) or text not in choices:
            shown = ", ".join((labels or {}).get(choice, repr(choice)) for choice in choices)
            raise self.error(field, f"expected one of {shown}, got {describe(value)}")
        return text

    # ---- files ------------------------------------------------------------------------------------

    def file(self, value, field: str, what: str = "file", *, resolve: bool = False) -> Path:
        """A file named relative to the document's folder (or absolute), which must exist; with
        `resolve` a relative name comes back as an absolute path, links followed."""
        if not isinstance(value, str) or not value:
            raise self.error(field, f"expected a file name, got {describe(value)}")
        if "\0" in value:
            raise self.error(field, "a file name cannot hold a NUL character")
        path = Path(value)
        if not path.is_absolute():
            path = self.folder / path
        shown, looked = describe(value), str(path) if len(str(path)) <= SHOWN_PATH else f"{str(path)[:SHOWN_PATH]}..."
        if is_dir(path):
            raise self.error(field, f"{what} {shown} is a folder, not a file ({looked})")
        if not is_file(path):
            problem = "is not a regular file" if exists(path) else "not found"
            raise self.error(field, f"{what} {shown} {problem} (looked for {looked})")
        return path.resolve() if resolve and not Path(value).is_absolute() else path

    def read_file(self, value, field: str, what: str = "file") -> bytes:
        """The bytes of the file `file` names; a read that fails is an error naming the field."""
        path = self.file(value, field, what)
        try:
            return read_bytes(path, what)
        except InputError as exc:
            raise self.error(field, str(exc)) from None
