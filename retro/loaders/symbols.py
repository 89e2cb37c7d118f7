"""Symbol files of the common 6502 assemblers -> plain `Symbol`s -> the tables a `Program` holds.

The format is recognised from the content, never from the file name (docs/symbols.md lists each
assembler's command line, every kind of line it writes, and what retro does with each):

- VICE labels, `al C:c000 .name` / `al c000 .name` / `al 00C000 .name`: ACME --vicelabels,
  64tass --vice-labels(-numeric) (scopes spelt `proc:loop`), ld65 -Ln (no scopes), Kick -vicesymbols
  (which may add `break`/`watch`/`trace` monitor commands).
- Kick Assembler -symbolfile `.sym`: `.label name=$1000`, `.const name=$fb`, `.namespace x { ... }`.
- ca65/ld65 `--dbgfile`: `scope` and `sym` lines (cc65 doc "dbginfo"); scopes give `proc::loop`.
- An equate list, `name = $c000` a line: ACME --symbollist (`!addr` prefix, `+2` suffix, `; ?` and
  `; unused` remarks) and 64tass --labels (any 64tass value: strings, floats, lists, `:=` variables).
- 64tass --dump-labels: `file:line:col: scope.name = $c000`.
- DASM -s: `name  c000  (R )` between `--- Symbol List` lines; `N.name` is a local of SUBROUTINE N.
- xa -l: `name, 0xc000, block, 0xseg`, with -r each followed by `file line line ...` references.

Every line an assembler writes is understood. A line that gives an address (0..$FFFF) is a symbol;
the others (DASM string macros and unresolved names, strings, floats, constants outside 0..$FFFF
such as negatives written as 32- or 64-bit values) are counted by kind and said once in the
`SymbolFile.note`. A line no assembler writes is a one-line error naming the file and the line.
Numbers are read strictly: no digit string is ever converted whole when it is longer than an
address can be, and a negative value is never wrapped into the address space.
"""

from __future__ import annotations

import re
from collections import Counter
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
class SkipKind:
    """A kind of line an assembler writes that names no address."""
    singular: str
    plural: str

    def counted(self, count: int) -> str:
        return f"{count} {self.singular if count == 1 else self.plural}"


STRING_MACRO = SkipKind("string macro", "string macros")  # DASM EQM
STRING = SkipKind("string constant", "string constants")  # DASM `str`, 64tass and Kick strings
UNRESOLVED = SkipKind("unresolved name", "unresolved names")  # DASM `????`, ACME `?`, 64tass gaps, xa imports
OUT_OF_RANGE = SkipKind("constant outside $0000-$FFFF", "constants outside $0000-$FFFF")  # negatives too
NOT_INTEGER = SkipKind("non-integer value", "non-integer values")  # floats, lists, booleans, bytes, ...
MONITOR_COMMAND = SkipKind("monitor command", "monitor commands")  # `break`/`watch`/`trace` in a .vs file
SKIP_KINDS = (STRING_MACRO, STRING, UNRESOLVED, OUT_OF_RANGE, NOT_INTEGER, MONITOR_COMMAND)

Skipped = Counter  # SkipKind -> number of lines of that kind


@dataclass(frozen=True)
class SymbolFile:
    source: str
    format: str  # the SymbolFormat's name; "" for an empty file
    symbols: tuple[Symbol, ...]
    skipped: tuple[tuple[SkipKind, int], ...] = ()  # in SKIP_KINDS order, kinds that occur only

    @property
    def note(self) -> str:
        """One line for the report when lines were skipped ("" when none was)."""
        if not self.skipped:
            return ""
        kinds = ", ".join(kind.counted(count) for kind, count in self.skipped)
        read = f"{len(self.symbols)} symbol{'' if len(self.symbols) == 1 else 's'}"
        return f"{self.source}: {read} read; skipped {kinds} (lines without an address)"


@dataclass(frozen=True)
class SymbolFormat:
    name: str
    detect: Callable[[str], bool]  # the first significant line -> is it this format?
    # (line number, line) pairs, source, the skip counter to add to -> symbols
    parse: Callable[[list[tuple[int, str]], str, Skipped], list[Symbol]]


# ---- helpers ---------------------------------------------------------------------------------

_COMMENT_PREFIXES = ("#", ";", "//")


def _significant_lines(text: str) -> list[tuple[int, str]]:
    return [(number, line.strip()) for number, line in enumerate(text.splitlines(), start=1)
            if line.strip() and not line.strip().startswith(_COMMENT_PREFIXES)]


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


# ---- numbers ---------------------------------------------------------------------------------

# A number with more significant digits than this is above $FFFF in base 10 and 16 alike; it is
# never converted (Python refuses decimal strings past 4,300 digits, and a huge hex number costs
# time for nothing): it is only known to be out of range.
_ADDRESS_DIGITS = 8
_ABOVE_ADDRESSES = ADDRESS_LIMIT + 1  # stands for any number too long to be converted


def _unsigned_value(digits: str, base: int) -> int:
    """Digits (no sign) -> their value, or _ABOVE_ADDRESSES when they cannot be an address."""
    significant = digits.lstrip("0")
    if len(significant) > _ADDRESS_DIGITS:
        return _ABOVE_ADDRESSES
    return int(significant or "0", base)


def _bounded_hex(digits: str, widest: int, what: str, source: str, number: int) -> int:
    """Hex digits of a format that writes at most `widest` of them (a C `%x` of its integer type)."""
    if len(digits) > widest:
        raise InputError(f"{source}:{number}: {len(digits)}-digit number in {what}; "
                         f"the assembler writes at most {widest} hex digits")
    return _unsigned_value(digits, 16)


def _address_or_skip(value: int, skipped: Skipped) -> int | None:
    if 0 <= value <= ADDRESS_LIMIT:
        return value
    skipped[OUT_OF_RANGE] += 1
    return None


# Values as 64tass and Kick Assembler print them (their own expression syntax). ACME's symbol list
# shares the line format and writes a subset: `$hex`, floats and `?`.
_INTEGER_VALUE = re.compile(r"^(?P<sign>[-~]?)(?:\$(?P<hex>[0-9A-Fa-f]+)|(?P<decimal>[0-9]+))$")
_FLOAT_VALUE = re.compile(r"^-?(?:[0-9]+\.[0-9]*(?:[eE][-+]?[0-9]+)?|[0-9]+[eE][-+]?[0-9]+|inf|nan)$")
_STRING_VALUE = re.compile(r"""^(?:"(?:[^"]|"")*"|'(?:[^']|'')*')$""")
_BYTES_VALUE = re.compile(r"""^[A-Za-z](?:"(?:[^"]|"")*"|'(?:[^']|'')*')$""")  # 64tass bytes: z'0S*', x"12"
_CALL_VALUE = re.compile(r"^[A-Za-z_]\w*\(.*\)$")  # 64tass objects: register("a")
_BRACKETS = {"[": "]", "(": ")", "{": "}"}  # 64tass lists, tuples, dictionaries
_WORD_VALUES = {"true", "false"}
_GAP = "?"  # 64tass: a name reserved without a value; ACME: a symbol never defined


def _classify_value(text: str) -> int | SkipKind | None:
    """An assembler's printed value -> an integer (any size: _ABOVE_ADDRESSES when it is too long,
    negative when signed), the kind of non-address it is, or None when no assembler prints it so."""
    match = _INTEGER_VALUE.match(text)
    if match:
        digits, base = (match.group("hex"), 16) if match.group("hex") is not None else (match.group("decimal"), 10)
        value = _unsigned_value(digits, base)
        if match.group("sign") == "-":
            return -value
        return ~value if match.group("sign") == "~" else value  # 64tass prints a negative bit string as ~$7f
    if _STRING_VALUE.match(text):
        return STRING
    if text == _GAP:
        return UNRESOLVED
    if (_FLOAT_VALUE.match(text) or _BYTES_VALUE.match(text) or _CALL_VALUE.match(text) or text in _WORD_VALUES
            or (text[:1] in _BRACKETS and text.endswith(_BRACKETS[text[:1]]))):
        return NOT_INTEGER
    return None


def _value_address(text: str, skipped: Skipped, source: str, number: int, line: str, expected: str) -> int | None:
    """A printed value -> its address, or None after counting why it gives none."""
    value = _classify_value(text)
    if value is None:
        raise _malformed(source, number, line, expected)
    if isinstance(value, SkipKind):
        skipped[value] += 1
        return None
    return _address_or_skip(value, skipped)


# ---- VICE labels -----------------------------------------------------------------------------

# ACME writes `%04x` of a 32-bit value (a negative as ffffff80), ld65 `%06lX` (FFFFFFF0), 64tass
# `%x` of up to 24 bits (ffff80): 16 digits is room for a 64-bit value, more is no assembler's
_VICE_DIGITS = 16
_VICE_LINE = re.compile(r"^al\s+(?:[Cc]:)?(?P<address>[0-9A-Fa-f]+)\s+\.?(?P<name>\S+)$")
# Kick Assembler's .vs carries its .break/.watch directives as VICE monitor commands
_VICE_COMMAND = re.compile(r"^(?:break|watch|trace)(?:\s.*)?$")


def _parse_vice(lines: list[tuple[int, str]], source: str, skipped: Skipped) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        match = _VICE_LINE.match(line)
        if not match:
            if _VICE_COMMAND.match(line):
                skipped[MONITOR_COMMAND] += 1
                continue
            raise _malformed(source, number, line, "'al C:ADDR .name'")
        name = match.group("name")
        address = _address_or_skip(_bounded_hex(match.group("address"), _VICE_DIGITS, f"the address of {name!r}",
                                                source, number), skipped)
        if address is not None:
            symbols.append(_scoped(name, ":.", address))  # 64tass writes `proc:loop`, Kick `ns.label`
    return symbols


# ---- Kick Assembler .sym ---------------------------------------------------------------------

# a name may also carry its scopes itself (`fill.loop`), besides sitting in a .namespace block
_KICK_SYMBOL = re.compile(r"^\.(?:label|const|var)\s+(?P<name>[A-Za-z_@][\w@.]*)\s*=\s*(?P<value>.+?)\s*$")
_KICK_NAMESPACE = re.compile(r"^\.namespace\s+(?P<name>[A-Za-z_@][\w@]*)\s*\{$")
_KICK_EXPECTED = "'.label name=$ADDR', '.const', '.namespace name {' or '}'"


def _parse_kick(lines: list[tuple[int, str]], source: str, skipped: Skipped) -> list[Symbol]:
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
            raise _malformed(source, number, line, _KICK_EXPECTED)
        address = _value_address(match.group("value"), skipped, source, number, line, _KICK_EXPECTED)
        if address is None:
            continue
        path = [*scopes, *match.group("name").split(".")]
        symbols.append(Symbol(name=path[-1], address=address, scope=SCOPE_SEPARATOR.join(path[:-1]),
                              spelling=".".join(path) if len(path) > 1 else ""))
    if scopes:
        raise InputError(f"{source}: .namespace {scopes[-1]} is not closed (file truncated?)")
    return symbols


# ---- ca65/ld65 debug file --------------------------------------------------------------------

_DBG_RECORD = re.compile(r"^(?P<kind>[a-z]+)\s+(?P<fields>.*)$")
_DBG_FIELD = re.compile(r'(?P<key>\w+)=(?P<value>"[^"]*"|[^,]*)')
# ld65 writes ids and counts in decimal and values as `0x%lX` of a long (cc65's own values are 32
# bits, so a negative one reads 0xFFFFFFF0): never a sign
_DBG_NUMBER = re.compile(r"^(?:0[xX](?P<hex>[0-9A-Fa-f]+)|(?P<decimal>[0-9]+))$")
_DBG_DIGITS = 16
_DBG_DECIMAL_DIGITS = 20  # ids and counts: `%u` of at most 64 bits


def _dbg_fields(line: str, source: str, number: int) -> tuple[str, dict[str, str]]:
    match = _DBG_RECORD.match(line)
    if not match:
        raise _malformed(source, number, line, "a 'kind key=value,...' record")
    fields = {m.group("key"): m.group("value").strip('"') for m in _DBG_FIELD.finditer(match.group("fields"))}
    return match.group("kind"), fields


def _dbg_int(fields: dict[str, str], key: str, source: str, number: int) -> int:
    match = _DBG_NUMBER.match(fields.get(key, ""))
    if not match:
        raise InputError(f"{source}:{number}: field {key!r} missing or not a number "
                         f"(ld65 writes 0x1234 or 1234, never a sign)")
    if match.group("hex") is not None:
        return _bounded_hex(match.group("hex"), _DBG_DIGITS, f"field {key!r}", source, number)
    if len(match.group("decimal")) > _DBG_DECIMAL_DIGITS:
        raise InputError(f"{source}:{number}: {len(match.group('decimal'))}-digit number in field {key!r}; "
                         f"ld65 writes at most {_DBG_DECIMAL_DIGITS} decimal digits")
    return int(match.group("decimal"))


def _parse_dbg(lines: list[tuple[int, str]], source: str, skipped: Skipped) -> list[Symbol]:
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

    scope_paths: dict[int, tuple[str, ...]] = {}  # each scope's path is walked once, however deep

    def scope_path(scope_id: int, number: int) -> tuple[str, ...]:
        chain, seen = [], set()
        while scope_id is not None and scope_id not in scope_paths:
            if scope_id in seen or scope_id not in scopes:
                raise InputError(f"{source}:{number}: scope {scope_id} is not defined in the file")
            seen.add(scope_id)
            chain.append(scope_id)
            scope_id = scopes[scope_id][1]
        path = scope_paths[scope_id] if scope_id is not None else ()
        for walked in reversed(chain):
            name = scopes[walked][0]
            path = (*path, name) if name else path
            scope_paths[walked] = path
        return path

    by_id = {_dbg_int(fields, "id", source, number): (number, fields) for number, fields in records}

    def symbol_path(fields: dict[str, str], number: int) -> tuple[str, ...]:
        """Scope path of a symbol: its scope's, or for a cheap local (`@loop`) its parent label's
        path and name (ca65 hangs a cheap local off a normal label, never off another cheap local)."""
        if "parent" not in fields:
            return scope_path(_dbg_int(fields, "scope", source, number), number)
        parent = _dbg_int(fields, "parent", source, number)
        if parent not in by_id or "parent" in by_id[parent][1]:
            raise InputError(f"{source}:{number}: the parent of this cheap local, symbol {parent}, "
                             f"is not a label defined in the file")
        parent_number, parent_fields = by_id[parent]
        return (*symbol_path(parent_fields, parent_number), parent_fields.get("name", ""))

    symbols = []
    for number, fields in records:
        if fields.get("type") == "imp" or "val" not in fields:
            continue  # an import names a symbol defined (with its value) elsewhere in the file
        address = _address_or_skip(_dbg_int(fields, "val", source, number), skipped)
        if address is None:
            continue
        path = symbol_path(fields, number)
        symbols.append(Symbol(name=fields.get("name", ""), address=address, scope=SCOPE_SEPARATOR.join(path)))
    return symbols


# ---- equate lists: ACME --symbollist, 64tass --labels ----------------------------------------

# ACME: `[!addr]\tname[+2|+3]\t= value[\t; ?][\t; unused]` (`!addr` with -Wtype-mismatch, `+2` a
# forced width, `; ?` a forward reference, `; unused` never read); 64tass: `name\t\t= value`, or
# `:=` for a variable, with any 64tass value up to the end of the line.
_EQUATE_LINE = re.compile(r"^(?:!addr\s*)?(?P<name>[A-Za-z_.@][\w.@]*)(?:\+[23])?\s*:?=\s*(?P<value>.*)$")
_ACME_VALUE = re.compile(r"^(?P<value>[^\s;]+)(?P<remarks>(?:\s*;\s*(?:\?|unused))*)$")
_WHOLE_LINE_VALUE = re.compile(r"""^(?:["'\[({]|[A-Za-z_]\w*\(|[A-Za-z]["'])""")  # may hold spaces and `;`
_EQUATE_EXPECTED = "'name = $ADDR'"


def _equate_value(text: str) -> str | None:
    """The value part of an equate (without ACME's remarks), None when the remarks are not ACME's."""
    if _WHOLE_LINE_VALUE.match(text):
        return text
    match = _ACME_VALUE.match(text)
    return match.group("value") if match else None


def _parse_equates(lines: list[tuple[int, str]], source: str, skipped: Skipped) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        match = _EQUATE_LINE.match(line)
        value = _equate_value(match.group("value")) if match else None
        if value is None:
            raise _malformed(source, number, line, _EQUATE_EXPECTED)
        address = _value_address(value, skipped, source, number, line, _EQUATE_EXPECTED)
        if address is not None:
            symbols.append(_scoped(match.group("name"), ".", address))
    return symbols


# ---- 64tass --dump-labels --------------------------------------------------------------------

_DUMP_LINE = re.compile(r"^(?P<file>.+?):(?P<line>\d+):(?P<column>\d+):\s+(?P<name>\S+)\s*:?=\s*(?P<value>.*?)\s*$")
_DUMP_EXPECTED = "'FILE:LINE:COLUMN: name = $ADDR'"


def _parse_tass_dump(lines: list[tuple[int, str]], source: str, skipped: Skipped) -> list[Symbol]:
    symbols = []
    for number, line in lines:
        match = _DUMP_LINE.match(line)
        if not match:
            raise _malformed(source, number, line, _DUMP_EXPECTED)
        address = _value_address(match.group("value"), skipped, source, number, line, _DUMP_EXPECTED)
        if address is not None:
            symbols.append(_scoped(match.group("name"), ".", address))
    return symbols


# ---- DASM -s ---------------------------------------------------------------------------------

# DASM's symbol dump (main.c ShowSymbols/sftos): `%-24s %-12s` of the name and of
# `%04lx ` + `???? ` (unresolved) + `str ` + `eqm ` + `(R )`/`( S)`/`(RS)`, then ` "text"` for a
# string. The value is a C long: a negative is 16 hex digits (ffffffffffffff80; 8 where long is 32
# bits), a string's is its bytes (616263 for "abc"), an EQM macro's 0000.
_DASM_HEADER = "--- Symbol List"  # then " (sorted by symbol)", " (sorted by address)", " (unsorted ...)"
_DASM_FOOTER = "--- End of Symbol List"
_DASM_LINE = re.compile(r'^(?P<name>\S+)\s+(?P<value>[0-9A-Fa-f]+)(?P<unresolved>\s+\?\?\?\?)?(?P<string>\s+str)?'
                        r'(?P<macro>\s+eqm)?(?:\s+\([R ][S ]\))?(?:\s+"(?P<text>.*)")?$')
_DASM_DIGITS = 16
_DASM_LOCAL = re.compile(r"^(?P<subroutine>\d+)(?P<separator>[.$])(?P<name>.+)$")  # `1.loop`, `1$1$`


def _dasm_symbol(name: str, address: int) -> Symbol:
    local = _DASM_LOCAL.match(name)
    if not local:
        return Symbol(name=name, address=address)
    # `.loop` of the first SUBROUTINE is `1.loop`; a `1$` label of the first block of `$` locals is
    # `1$1$`: DASM writes the block's number, not a name
    return Symbol(name=local.group("name"), address=address, scope=local.group("subroutine"), spelling=name)


def _parse_dasm(lines: list[tuple[int, str]], source: str, skipped: Skipped) -> list[Symbol]:
    symbols, ended = [], False
    for number, line in lines:
        if line.startswith("---"):
            if line.startswith(_DASM_FOOTER) and not ended:
                ended = True
            elif not line.startswith(_DASM_HEADER) or number != lines[0][0]:
                raise _malformed(source, number, line, f"one '{_DASM_HEADER} ...' and one '{_DASM_FOOTER}.'")
            continue
        match = _DASM_LINE.match(line)
        if not match or ended or bool(match.group("string")) != (match.group("text") is not None):
            raise _malformed(source, number, line, "'name  ADDR  (flags)' before the end of the list")
        name = match.group("name")
        value = _bounded_hex(match.group("value"), _DASM_DIGITS, f"the value of {name!r}", source, number)
        if match.group("macro"):
            skipped[STRING_MACRO] += 1
        elif match.group("unresolved"):
            skipped[UNRESOLVED] += 1
        elif match.group("string"):
            skipped[STRING] += 1
        else:
            address = _address_or_skip(value, skipped)
            if address is not None:
                symbols.append(_dasm_symbol(name, address))
    if not ended:
        raise InputError(f"{source}: truncated: no '{_DASM_FOOTER}.' line (DASM always ends the list with it)")
    return list(dict.fromkeys(symbols))


# ---- xa -l -----------------------------------------------------------------------------------

# xa's printllist: `%s, 0x%04x, %d, 0x%04x` (name, value, block, segment), and with -r after each
# symbol the lines that reference it, `    FILE LINE LINE ...`. The segment 1 is "undefined": a
# label given with -L and never defined.
_XA_LINE = re.compile(r"^(?P<name>[A-Za-z_@][\w]*),\s*0x(?P<address>[0-9A-Fa-f]+),\s*(?P<block>\d+),"
                      r"\s*0x(?P<segment>[0-9A-Fa-f]+)$")
_XA_DIGITS = 8  # a C int
_XA_UNDEFINED_SEGMENT = 1


def _is_xa_references(line: str) -> bool:
    """`file.asm 7 9`: a file name (no comma) and one or more line numbers (split, not a regex: a
    pattern for it backtracks quadratically on a long line of numbers)."""
    words = line.split()
    line_numbers = next((i for i, word in enumerate(reversed(words)) if not word.isdecimal()), len(words))
    return 0 < line_numbers < len(words) and "," not in line


def _parse_xa(lines: list[tuple[int, str]], source: str, skipped: Skipped) -> list[Symbol]:
    symbols, after_symbol = [], False
    for number, line in lines:
        match = _XA_LINE.match(line)
        if not match:
            if after_symbol and _is_xa_references(line):
                continue  # -r: where the symbol above is used
            raise _malformed(source, number, line, "'name, 0xADDR, BLOCK, 0xSEG'")
        after_symbol = True
        name = match.group("name")
        value = _bounded_hex(match.group("address"), _XA_DIGITS, f"the value of {name!r}", source, number)
        if _bounded_hex(match.group("segment"), _XA_DIGITS, "the segment", source, number) == _XA_UNDEFINED_SEGMENT:
            skipped[UNRESOLVED] += 1
            continue
        address = _address_or_skip(value, skipped)
        # the block is xa's internal number for a `.(` ... `.)` block, which sources never name:
        # a name defined in two blocks is told apart by its address instead
        if address is not None:
            symbols.append(Symbol(name=name, address=address))
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


def parse_symbol_file(text: str, source: str = "symbols") -> SymbolFile:
    """A symbol file's text in any known format -> its symbols (in file order) and what was skipped."""
    lines = _significant_lines(text)
    if not lines:
        return SymbolFile(source=source, format="", symbols=())
    symbol_format = detect_format(text)
    if symbol_format is None:
        tried = ", ".join(f.name for f in FORMATS)
        raise InputError(f"{source}: not a symbol file in a known format (tried {tried})")
    skipped: Skipped = Counter()
    symbols = symbol_format.parse(lines, source, skipped)
    return SymbolFile(source=source, format=symbol_format.name, symbols=tuple(symbols),
                      skipped=tuple((kind, skipped[kind]) for kind in SKIP_KINDS if skipped[kind]))


def parse_symbols(text: str, source: str = "symbols") -> list[Symbol]:
    """A symbol file's text in any known format -> its symbols, in file order."""
    return list(parse_symbol_file(text, source).symbols)


def read_symbol_file(path: str | Path) -> SymbolFile:
    """Read and parse a symbol file; binary junk is an error naming the file."""
    data = read_bytes(path, "symbol file")
    if b"\0" in data:
        raise InputError(f"{path}: not a symbol file (binary data); pass the assembler's text symbol file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")  # older tools write 8-bit names; the names that matter are ASCII
    return parse_symbol_file(text, source=str(path))


def read_symbols(path: str | Path) -> list[Symbol]:
    return list(read_symbol_file(path).symbols)


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
    by_qualified = _addresses_by_qualified_name(symbols)
    for qualified, addresses in by_qualified.items():
        if len(addresses) == 1:
            table[qualified] = addresses[0]
        else:
            candidates = _spellings(by_qualified, qualified)
            ambiguous[qualified] = tuple(candidates)
            table.update(zip(candidates, addresses))
    by_name: dict[str, list[Symbol]] = {}
    for symbol in symbols:
        by_name.setdefault(symbol.name, []).append(symbol)
    for name, definitions in by_name.items():
        _bare_name(name, definitions, by_qualified, table, ambiguous)
    for symbol in symbols:  # the file's own spelling, where it names one address
        if symbol.spelling and symbol.spelling not in table and len(by_qualified[symbol.qualified]) == 1:
            table[symbol.spelling] = symbol.address
    return table, ambiguous


def _addresses_by_qualified_name(symbols: list[Symbol]) -> dict[str, list[int]]:
    by_qualified: dict[str, list[int]] = {}
    for symbol in symbols:
        addresses = by_qualified.setdefault(symbol.qualified, [])
        if symbol.address not in addresses:
            addresses.append(symbol.address)
    for addresses in by_qualified.values():
        addresses.sort()  # candidates are listed by address
    return by_qualified


def _spellings(by_qualified: dict[str, list[int]], qualified: str) -> list[str]:
    """The names that each pick out one definition of a qualified name."""
    addresses = by_qualified[qualified]
    if len(addresses) == 1:
        return [qualified]
    return [f"{qualified}@${address:04X}" for address in addresses]


def _bare_name(name: str, definitions: list[Symbol], by_qualified: dict[str, list[int]], table: dict[str, int],
               ambiguous: dict[str, tuple[str, ...]]) -> None:
    """Enter a bare name with scoped definitions: its address when all agree, else its candidates."""
    scoped = [s for s in definitions if s.scope]
    if not scoped:
        return  # a global's bare name is its qualified name: already entered
    addresses = {s.address for s in definitions}
    if len(addresses) == 1 and name not in ambiguous:
        table.setdefault(name, addresses.pop())
        return
    candidates: list[tuple[int, str]] = []  # (address, name), listed by address
    if name in by_qualified:  # a global of that name as well
        if len(by_qualified[name]) == 1:
            table[ROOT_PREFIX + name] = by_qualified[name][0]
            candidates.append((by_qualified[name][0], ROOT_PREFIX + name))
        else:
            candidates.extend(zip(by_qualified[name], _spellings(by_qualified, name)))
    for qualified in dict.fromkeys(s.qualified for s in scoped):
        candidates.extend(zip(by_qualified[qualified], _spellings(by_qualified, qualified)))
    ambiguous[name] = tuple(spelling for _, spelling in sorted(candidates))
    table.pop(name, None)


def load_symbol_tables(path: str | Path) -> tuple[dict[str, int], dict[str, tuple[str, ...]]]:
    return symbol_tables(read_symbols(path))
