"""Symbol files of the common 6502 assemblers -> plain `Symbol`s -> the tables a `Program` holds.

The format is recognised from the content, never from the file name (docs/symbols.md lists each
assembler's command line and what it writes):

- VICE labels, `al C:c000 .name` / `al c000 .name` / `al 00C000 .name`: ACME --vicelabels,
  64tass --vice-labels(-numeric) (scopes spelt `proc:loop`), ld65 -Ln (no scopes), Kick -vicesymbols.
- Kick Assembler -symbolfile `.sym`: `.label name=$1000`, `.const name=$fb`, `.namespace x { ... }`.
- ca65/ld65 `--dbgfile`: `scope` and `sym` lines (cc65 doc "dbginfo"); scopes give `proc::loop`.
- An equate list, `name = $c000` a line: ACME --symbollist (`; ?` remarks) and 64tass --labels.
- 64tass --dump-labels: `file:line:col: scope.name = $c000`.
- DASM -s: `name  c000  (R )` between `--- Symbol List` lines; `N.name` is a local of SUBROUTINE N.
- xa -l: `name, 0xc000, block, 0x0000`; the block is a number, not a name.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from retro.errors import InputError
from retro.fileio import read_bytes
from retro.program import ADDRESS_LIMIT

SCOPE_SEPARATOR = "::"  # ca65's spelling; every format's scoped names are also reachable this way
ROOT_PREFIX = "::"  # `::loop` names the global `loop` when scopes also define one (ca65's spelling)


@dataclass(frozen=True)
class Symbol:
    name: str
    address: int
    scope: str = ""  # "" for globals, else the scope path joined by "::" ("outer::proc")
    spelling: str = ""  # the file's own spelling of the qualified name when it differs ("sum:loop", "1.loop")

    @property
    def qualified(self) -> str:
        return f"{self.scope}{SCOPE_SEPARATOR}{self.name}" if self.scope else self.name


@dataclass(frozen=True)
class SymbolFormat:
    name: str
    detect: Callable[[str], bool]  # the first significant line -> is it this format?
    parse: Callable[[list[tuple[int, str]], str], list[Symbol]]  # (line number, line) pairs, source


# ---- helpers ---------------------------------------------------------------------------------

_COMMENT_PREFIXES = ("#", ";", "//")


def _significant_lines(text: str) -> list[tuple[int, str]]:
    return [(number, line.strip()) for number, line in enumerate(text.splitlines(), start=1)
            if line.strip() and not line.strip().startswith(_COMMENT_PREFIXES)]


def _checked_address(value: int, name: str, source: str, number: int) -> int:
    if value > ADDRESS_LIMIT:
        raise InputError(f"{source}:{number}: value ${value:X} of {name!r} is above ${ADDRESS_LIMIT:04X}")
    return value


def _malformed(source: str, number: int, line: str, expected: str) -> InputError:
    return InputError(f"{source}:{number}: expected {expected}, got {line[:60]!r}")


def _split_path(qualified: str, separators: str) -> tuple[str, str]:
    """'a.b.c' -> ('a::b', 'c') for the given separator characters."""
    parts = [part for part in re.split(f"[{re.escape(separators)}]", qualified)]
    if len(parts) == 1 or not all(parts):
        return "", qualified
    return SCOPE_SEPARATOR.join(parts[:-1]), parts[-1]


def _scoped(qualified: str, separators: str, address: int) -> Symbol:
    scope, name = _split_path(qualified, separators)
    return Symbol(name=name, address=address, scope=scope, spelling=qualified if scope else "")


# Integer values as the formats write them; anything else (strings, floats, lists) is a constant that
# cannot be an address, and is left out.
_HEX_DOLLAR = re.compile(r"^\$([0-9A-Fa-f]+)$")
_DECIMAL = re.compile(r"^([0-9]+)$")


def _integer(text: str) -> int | None:
    match = _HEX_DOLLAR.match(text)
    if match:
        return int(match.group(1), 16)
    match = _DECIMAL.match(text)
    return int(text) if match else None


# ---- VICE labels -----------------------------------------------------------------------------

_VICE_LINE = re.compile(r"^al\s+(?:[Cc]:)?(?P<address>[0-9A-Fa-f]{1,6})\s+\.?(?P<name>\S+)$")


def _parse_vice(lines: list[tuple[int, str]], source: str) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        match = _VICE_LINE.match(line)
        if not match:
            raise _malformed(source, number, line, "'al C:ADDR .name'")
        name = match.group("name")
        address = _checked_address(int(match.group("address"), 16), name, source, number)
        symbols.append(_scoped(name, ":.", address))  # 64tass writes `proc:loop`, Kick `ns.label`
    return symbols


# ---- Kick Assembler .sym ---------------------------------------------------------------------

# a name may also carry its scopes itself (`fill.loop`), besides sitting in a .namespace block
_KICK_SYMBOL = re.compile(r"^\.(?:label|const|var)\s+(?P<name>[A-Za-z_@][\w@.]*)\s*=\s*(?P<value>.+?)\s*$")
_KICK_NAMESPACE = re.compile(r"^\.namespace\s+(?P<name>[A-Za-z_@][\w@]*)\s*\{$")


def _parse_kick(lines: list[tuple[int, str]], source: str) -> list[Symbol]:
    symbols, scopes = [], []
    for number, line in lines:
        if line == "}":
            if not scopes:
                raise InputError(f"{source}:{number}: '}}' closes no .namespace")
            scopes.pop()
            continue
        namespace = _KICK_NAMESPACE.match(line)
        if namespace:
            scopes.append(namespace.group("name"))
            continue
        match = _KICK_SYMBOL.match(line)
        if not match:
            raise _malformed(source, number, line, "'.label name=$ADDR', '.const', '.namespace name {' or '}'")
        value = _integer(match.group("value"))
        if value is None:
            continue  # a string or float constant: not an address
        path = [*scopes, *match.group("name").split(".")]
        address = _checked_address(value, match.group("name"), source, number)
        symbols.append(Symbol(name=path[-1], address=address, scope=SCOPE_SEPARATOR.join(path[:-1]),
                              spelling=".".join(path) if len(path) > 1 else ""))
    if scopes:
        raise InputError(f"{source}: .namespace {scopes[-1]} is not closed (file truncated?)")
    return symbols


# ---- ca65/ld65 debug file --------------------------------------------------------------------

_DBG_RECORD = re.compile(r"^(?P<kind>[a-z]+)\s+(?P<fields>.*)$")
_DBG_FIELD = re.compile(r'(?P<key>\w+)=(?P<value>"[^"]*"|[^,]*)')


def _dbg_fields(line: str, source: str, number: int) -> tuple[str, dict[str, str]]:
    match = _DBG_RECORD.match(line)
    if not match:
        raise _malformed(source, number, line, "a 'kind key=value,...' record")
    fields = {m.group("key"): m.group("value").strip('"') for m in _DBG_FIELD.finditer(match.group("fields"))}
    return match.group("kind"), fields


def _dbg_int(fields: dict[str, str], key: str, source: str, number: int) -> int:
    try:
        return int(fields[key], 0)
    except (KeyError, ValueError):
        raise InputError(f"{source}:{number}: field {key!r} missing or not a number") from None


def _parse_dbg(lines: list[tuple[int, str]], source: str) -> list[Symbol]:
    scopes: dict[int, tuple[str, int | None]] = {}  # id -> (name, parent id)
    records: list[tuple[int, dict[str, str]]] = []
    promised: dict[str, int] = {}  # the `info` line counts every kind of record: a cut file is caught
    for number, line in lines:
        kind, fields = _dbg_fields(line, source, number)
        if kind == "info":
            promised = {key: _dbg_int(fields, key, source, number) for key in ("scope", "sym") if key in fields}
        elif kind == "scope":
            parent = _dbg_int(fields, "parent", source, number) if "parent" in fields else None
            scopes[_dbg_int(fields, "id", source, number)] = (fields.get("name", ""), parent)
        elif kind == "sym":
            records.append((number, fields))
    for kind, found in (("scope", len(scopes)), ("sym", len(records))):
        if kind in promised and promised[kind] != found:
            raise InputError(f"{source}: truncated: its info line promises {promised[kind]} {kind} records, "
                             f"the file has {found}")

    def scope_path(scope_id: int, number: int) -> list[str]:
        path, seen = [], set()
        while scope_id is not None:
            if scope_id in seen or scope_id not in scopes:
                raise InputError(f"{source}:{number}: scope {scope_id} is not defined in the file")
            seen.add(scope_id)
            name, scope_id = scopes[scope_id]
            if name:
                path.append(name)
        return path[::-1]

    by_id = {_dbg_int(fields, "id", source, number): (number, fields) for number, fields in records}
    qualified_paths: dict[int, list[str]] = {}

    def symbol_path(symbol_id: int, number: int, depth: int = 0) -> list[str]:
        """Scope path of a symbol: its scope's, or for a cheap local (`@loop`) its parent label's."""
        if symbol_id in qualified_paths:
            return qualified_paths[symbol_id]
        if symbol_id not in by_id or depth > len(by_id):
            raise InputError(f"{source}:{number}: symbol {symbol_id} is not defined in the file")
        line_number, fields = by_id[symbol_id]
        if "parent" in fields:
            parent = _dbg_int(fields, "parent", source, line_number)
            path = [*symbol_path(parent, line_number, depth + 1), by_id[parent][1].get("name", "")] \
                if parent in by_id else []
        else:
            path = scope_path(_dbg_int(fields, "scope", source, line_number), line_number)
        qualified_paths[symbol_id] = path
        return path

    symbols = []
    for number, fields in records:
        if fields.get("type") == "imp" or "val" not in fields:
            continue  # an import names a symbol defined (with its value) elsewhere in the file
        name = fields.get("name", "")
        path = symbol_path(_dbg_int(fields, "id", source, number), number)
        address = _checked_address(_dbg_int(fields, "val", source, number), name, source, number)
        symbols.append(Symbol(name=name, address=address, scope=SCOPE_SEPARATOR.join(path)))
    return symbols


# ---- equate lists: ACME --symbollist, 64tass --labels ----------------------------------------

_EQUATE_LINE = re.compile(r"^(?P<name>[A-Za-z_.@][\w.@]*)\s*=\s*(?P<value>[^;]*?)\s*(?:;.*)?$")


def _parse_equates(lines: list[tuple[int, str]], source: str) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        match = _EQUATE_LINE.match(line)
        if not match:
            raise _malformed(source, number, line, "'name = $ADDR'")
        value = _integer(match.group("value"))
        if value is None:
            continue  # 64tass lists strings, floats, lists and negative numbers too: none is an address
        name = match.group("name")
        symbols.append(_scoped(name, ".", _checked_address(value, name, source, number)))
    return symbols


# ---- 64tass --dump-labels --------------------------------------------------------------------

_DUMP_LINE = re.compile(r"^(?P<file>.+?):(?P<line>\d+):(?P<column>\d+):\s+(?P<name>\S+)\s*=\s*(?P<value>.*?)\s*$")


def _parse_tass_dump(lines: list[tuple[int, str]], source: str) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        match = _DUMP_LINE.match(line)
        if not match:
            raise _malformed(source, number, line, "'FILE:LINE:COLUMN: name = $ADDR'")
        value = _integer(match.group("value"))
        if value is None:
            continue
        name = match.group("name")
        symbols.append(_scoped(name, ".", _checked_address(value, name, source, number)))
    return symbols


# ---- DASM -s ---------------------------------------------------------------------------------

_DASM_HEADER = "--- Symbol List"
_DASM_FOOTER = "--- End of Symbol List"
_DASM_LINE = re.compile(r'^(?P<name>\S+)\s+(?P<value>[0-9A-Fa-f]+|"[^"]*"|\S+)(?:\s+\((?P<flags>[^)]*)\))?$')
_DASM_LOCAL = re.compile(r"^(?P<subroutine>\d+)\.(?P<name>.+)$")


def _parse_dasm(lines: list[tuple[int, str]], source: str) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        if line.startswith("---"):
            if not line.startswith((_DASM_HEADER, _DASM_FOOTER)):
                raise _malformed(source, number, line, f"'{_DASM_HEADER} ...' or '{_DASM_FOOTER}.'")
            continue
        match = _DASM_LINE.match(line)
        if not match:
            raise _malformed(source, number, line, "'name  ADDR  (flags)'")
        value = match.group("value")
        if not re.fullmatch(r"[0-9A-Fa-f]+", value):
            continue  # a string value or an unresolved symbol
        name = match.group("name")
        address = _checked_address(int(value, 16), name, source, number)
        local = _DASM_LOCAL.match(name)
        if local:  # `1.loop`: the local `.loop` of the first SUBROUTINE; DASM writes the number, not a name
            symbols.append(Symbol(name=local.group("name"), address=address, scope=local.group("subroutine"),
                                  spelling=name))
        else:
            symbols.append(Symbol(name=name, address=address))
    # -T1 sorts by address and writes every symbol again: one copy is enough
    return list(dict.fromkeys(symbols))


# ---- xa -l -----------------------------------------------------------------------------------

_XA_LINE = re.compile(r"^(?P<name>[A-Za-z_][\w]*),\s*0x(?P<address>[0-9A-Fa-f]+),\s*(?P<block>\d+),\s*0x[0-9A-Fa-f]+$")


def _parse_xa(lines: list[tuple[int, str]], source: str) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        match = _XA_LINE.match(line)
        if not match:
            raise _malformed(source, number, line, "'name, 0xADDR, BLOCK, 0xSEG'")
        name = match.group("name")
        # the block is xa's internal number for a `.(` ... `.)` block, which sources never name:
        # a name defined in two blocks is told apart by its address instead
        symbols.append(Symbol(name=name, address=_checked_address(int(match.group("address"), 16), name, source,
                                                                  number)))
    return symbols


FORMATS: tuple[SymbolFormat, ...] = (
    SymbolFormat("ca65/ld65 --dbgfile", lambda line: line.startswith("version") and "major=" in line, _parse_dbg),
    SymbolFormat("DASM -s", lambda line: line.startswith(_DASM_HEADER), _parse_dasm),
    SymbolFormat("VICE labels", lambda line: _VICE_LINE.match(line) is not None, _parse_vice),
    SymbolFormat("Kick Assembler .sym", lambda line: line.startswith((".label", ".const", ".var", ".namespace")),
                 _parse_kick),
    SymbolFormat("64tass --dump-labels", lambda line: _DUMP_LINE.match(line) is not None, _parse_tass_dump),
    SymbolFormat("xa -l", lambda line: _XA_LINE.match(line) is not None, _parse_xa),
    SymbolFormat("ACME --symbollist / 64tass --labels", lambda line: _EQUATE_LINE.match(line) is not None,
                 _parse_equates),
)


def detect_format(text: str) -> SymbolFormat | None:
    """The format whose first significant line this text starts with; None for an empty file."""
    lines = _significant_lines(text)
    if not lines:
        return None
    for candidate in FORMATS:
        if candidate.detect(lines[0][1]):
            return candidate
    return None


def parse_symbols(text: str, source: str = "symbols") -> list[Symbol]:
    """A symbol file's text in any known format -> its symbols, in file order."""
    lines = _significant_lines(text)
    if not lines:
        return []
    symbol_format = detect_format(text)
    if symbol_format is None:
        tried = ", ".join(f.name for f in FORMATS)
        raise InputError(f"{source}: not a symbol file in a known format (tried {tried})")
    return symbol_format.parse(lines, source)


def read_symbols(path: str | Path) -> list[Symbol]:
    """Read and parse a symbol file; binary junk is an error naming the file."""
    data = read_bytes(path, "symbol file")
    if b"\0" in data:
        raise InputError(f"{path}: not a symbol file (binary data); pass the assembler's text symbol file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")  # older tools write 8-bit names; the names that matter are ASCII
    return parse_symbols(text, source=str(path))


def symbol_tables(symbols: Iterable[Symbol]) -> tuple[dict[str, int], dict[str, tuple[str, ...]]]:
    """Symbols -> ({name: address}, {ambiguous bare name: candidate names}).

    Every symbol is reachable by its qualified name (`proc::loop`) and by the file's own spelling
    (`proc.loop`, `proc:loop`, `1.loop`). A bare name is in the table only when all its definitions
    name one address; otherwise it is ambiguous and its candidates are listed: their qualified
    names, `::loop` for a global beside scoped ones, and `loop@$C005` where the file gives two
    addresses to one name with no scope to tell them apart (ld65 -Ln, xa)."""
    symbols = list(dict.fromkeys(symbols))
    table: dict[str, int] = {}
    ambiguous: dict[str, tuple[str, ...]] = {}

    by_qualified: dict[str, list[int]] = {}
    for symbol in symbols:
        addresses = by_qualified.setdefault(symbol.qualified, [])
        if symbol.address not in addresses:
            addresses.append(symbol.address)
    for addresses in by_qualified.values():
        addresses.sort()  # candidates are listed by address

    def spellings(qualified: str) -> list[str]:
        """The names that each pick out one definition of a qualified name."""
        addresses = by_qualified[qualified]
        if len(addresses) == 1:
            return [qualified]
        return [f"{qualified}@${address:04X}" for address in addresses]

    for qualified, addresses in by_qualified.items():
        if len(addresses) == 1:
            table[qualified] = addresses[0]
        else:
            candidates = spellings(qualified)
            ambiguous[qualified] = tuple(candidates)
            table.update(zip(candidates, addresses))

    by_name: dict[str, list[Symbol]] = {}
    for symbol in symbols:
        by_name.setdefault(symbol.name, []).append(symbol)
    for name, definitions in by_name.items():
        scoped = [s for s in definitions if s.scope]
        if not scoped:
            continue  # a global's bare name is its qualified name: handled above
        addresses = {s.address for s in definitions}
        if len(addresses) == 1 and name not in ambiguous:
            table.setdefault(name, addresses.pop())
            continue
        candidates: list[tuple[int, str]] = []  # (address, name), listed by address
        if name in by_qualified:  # a global of that name as well
            if len(by_qualified[name]) == 1:
                table[ROOT_PREFIX + name] = by_qualified[name][0]
                candidates.append((by_qualified[name][0], ROOT_PREFIX + name))
            else:
                candidates.extend(zip(by_qualified[name], spellings(name)))
        for qualified in dict.fromkeys(s.qualified for s in scoped):
            candidates.extend(zip(by_qualified[qualified], spellings(qualified)))
        ambiguous[name] = tuple(spelling for _, spelling in sorted(candidates))
        table.pop(name, None)

    for symbol in symbols:  # the file's own spelling, where it names one address
        if symbol.spelling and symbol.spelling not in table and len(by_qualified[symbol.qualified]) == 1:
            table[symbol.spelling] = symbol.address
    return table, ambiguous


def load_symbol_tables(path: str | Path) -> tuple[dict[str, int], dict[str, tuple[str, ...]]]:
    return symbol_tables(read_symbols(path))
