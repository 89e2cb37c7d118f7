"""Which source line each byte of a program came from, as the assemblers write it: the ca65/ld65
debug file (`ld65 --dbgfile`: its `file`, `seg`, `span` and `line` records, cc65 doc "dbginfo") and
ACME's report (`acme --report FILE`). The coverage reports (LCOV, HTML) map instructions to the
user's lines with it (docs/coverage.md).

A 64tass listing (`-L`) is refused with the reason: 64tass 1.58 writes no line number for the lines
of the main file, even with `--line-numbers` (tried on Debian 12's 64tass), and its macro expansions
show the expanded text without the line that called them, so a listing cannot be mapped back to lines
reliably.

Source files are named as the assembler wrote them; a relative name is resolved against the folder
of the file that names it when the source is there (the usual layout), else kept as written."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from retro.errors import InputError
from retro.fileio import is_file, read_text
from retro.loaders.symbols import dbg_fields, dbg_int

ADDRESS_SPACE = 0x10000
# ca65 line types (cc65 dbginfo.h: LINE_ASM 0, LINE_EXT 1, LINE_MACRO 2): a byte named by several
# lines takes the C source line (cc65-compiled code) first, then the assembler line that was written
# there (a macro's call), then the line inside a macro's body
_DBG_LINE_PREFERENCE = {1: 0, 0: 1, 2: 2}


@dataclass(frozen=True)
class SourceLine:
    file: str  # the source file (resolved when found beside the file that names it)
    line: int  # 1-based


@dataclass(frozen=True)
class SourceMap:
    source: str  # the debug file or report it was read from
    format: str
    lines: dict[int, SourceLine]  # address -> the line that produced the byte there

    def line_of(self, address: int) -> SourceLine | None:
        return self.lines.get(address)


def _resolved_name(name: str, beside: str) -> str:
    path = Path(name)
    if path.is_absolute():
        return name
    candidate = Path(beside).parent / path
    return str(candidate.resolve()) if is_file(candidate) else name


# ---- ca65/ld65 --dbgfile ---------------------------------------------------------------------

def _parse_dbg(text: str, source: str) -> dict[int, SourceLine]:
    """address -> the line that produced its byte: where several lines cover one address, the line
    of the kind `_DBG_LINE_PREFERENCE` ranks first, then the smallest span."""
    files, segments, spans, line_records = _dbg_records(text, source)
    best: dict[int, tuple[tuple[int, int], SourceLine]] = {}  # address -> (preference, line)
    names = {file_id: _resolved_name(name, source) for file_id, name in files.items()}
    for number, fields in line_records:
        file_id = dbg_int(fields, "file", source, number)
        if file_id not in names:
            raise InputError(f"{source}:{number}: file {file_id} is not defined in the file")
        where = SourceLine(names[file_id], dbg_int(fields, "line", source, number))
        kind = dbg_int(fields, "type", source, number) if "type" in fields else 0
        for first, size in _line_spans(fields["span"], spans, segments, source, number):
            preference = (_DBG_LINE_PREFERENCE.get(kind, len(_DBG_LINE_PREFERENCE)), size)
            for address in range(first, first + size):
                if address not in best or preference < best[address][0]:
                    best[address] = (preference, where)
    return {address: where for address, (_, where) in best.items()}


def _dbg_records(text: str, source: str) -> tuple[dict, dict, dict, list]:
    """The records of a --dbgfile the lines need: files (id -> name), segments (id -> start address),
    spans (id -> (segment, start in it, size)) and the line records that name spans."""
    files: dict[int, str] = {}
    segments: dict[int, int] = {}
    spans: dict[int, tuple[int, int, int]] = {}
    line_records: list[tuple[int, dict[str, str]]] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        if not raw.strip():
            continue
        kind, fields = dbg_fields(raw.strip(), source, number)
        if kind == "file":
            files[dbg_int(fields, "id", source, number)] = fields.get("name", "")
        elif kind == "seg":
            segments[dbg_int(fields, "id", source, number)] = dbg_int(fields, "start", source, number)
        elif kind == "span":
            spans[dbg_int(fields, "id", source, number)] = (
                dbg_int(fields, "seg", source, number), dbg_int(fields, "start", source, number),
                dbg_int(fields, "size", source, number))
        elif kind == "line" and fields.get("span"):
            line_records.append((number, fields))
    return files, segments, spans, line_records


def _line_spans(text: str, spans: dict, segments: dict, source: str, number: int) -> list[tuple[int, int]]:
    """A line record's `span=A+B` -> (first address, size) of each span inside the 6502's address
    space (a bank's file offsets have no address to map)."""
    out = []
    for span_text in text.split("+"):
        if not span_text.isdigit() or int(span_text) not in spans:
            raise InputError(f"{source}:{number}: span {span_text!r} is not defined in the file")
        segment, start, size = spans[int(span_text)]
        if segment not in segments:
            raise InputError(f"{source}:{number}: segment {segment} is not defined in the file")
        first = segments[segment] + start
        if size <= ADDRESS_SPACE and first + size <= ADDRESS_SPACE:
            out.append((first, size))
    return out


# ---- ACME --report ---------------------------------------------------------------------------

_ACME_SOURCE = re.compile(r"^; \*{8} Source: (?P<name>.+)$")
# `   11  c000 ad4bc0          lda boxb_x`: line, address, the bytes (at most 8, then `...`), source
_ACME_BYTES_LINE = re.compile(r"^\s*(?P<line>\d+)\s+(?P<address>[0-9a-fA-F]{4,})\s+(?P<hex>(?:[0-9a-fA-F]{2})+)(?P<more>\.\.\.)?")


def _parse_acme(text: str, source: str) -> dict[int, SourceLine]:
    current = ""
    starts: list[tuple[int, int, bool, SourceLine]] = []  # (address, bytes shown, cut, line)
    for number, raw in enumerate(text.splitlines(), start=1):
        header = _ACME_SOURCE.match(raw)
        if header:
            current = _resolved_name(header.group("name").strip(), source)
            continue
        match = _ACME_BYTES_LINE.match(raw)
        if not match:
            continue
        if not current:
            raise InputError(f"{source}:{number}: a line with bytes before any '; ******** Source:' line")
        address = int(match.group("address"), 16)
        if address >= ADDRESS_SPACE:
            raise InputError(f"{source}:{number}: address ${address:X} is above $FFFF")
        starts.append((address, len(match.group("hex")) // 2, match.group("more") is not None,
                       SourceLine(current, int(match.group("line")))))
    lines: dict[int, SourceLine] = {}
    for index, (address, shown, cut, where) in enumerate(starts):
        end = address + shown
        if cut:  # ACME shows 8 bytes then `...`: the line runs on to the next line's bytes
            following = [a for a, *_ in starts[index + 1:index + 2] if a > address]
            end = following[0] if following else end
        for byte in range(address, min(end, ADDRESS_SPACE)):
            lines.setdefault(byte, where)
    return lines


# ---- detection -------------------------------------------------------------------------------

def parse_source_map(text: str, source: str) -> SourceMap:
    first = next((line.strip() for line in text.splitlines() if line.strip()), "")
    if first.startswith("version") and "major=" in first:
        return SourceMap(source, "ca65/ld65 --dbgfile", _parse_dbg(text, source))
    if _ACME_SOURCE.match(first):
        return SourceMap(source, "ACME --report", _parse_acme(text, source))
    if first.startswith("; 64tass"):
        raise InputError(f"{source}: a 64tass listing gives no line numbers for the main file's lines, so it "
                         f"cannot map code to lines (without a listing, coverage is reported by address)")
    raise InputError(f"{source}: not a source map retro reads (an ld65 --dbgfile debug file or an ACME --report "
                     f"listing)")


def read_source_map(path: str | Path) -> SourceMap:
    return parse_source_map(read_text(path, "source listing"), str(path))


def has_line_information(path: str | Path) -> bool:
    """Whether a symbol file also maps bytes to lines (an ld65 debug file does)."""
    text = read_text(path, "symbol file")
    first = next((line.strip() for line in text.splitlines() if line.strip()), "")
    return first.startswith("version") and "major=" in first
