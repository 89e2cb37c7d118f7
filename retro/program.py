"""A loaded 6502 program (bytes at an origin, with symbols), and the PRG / VICE label formats.

PRG: a 2-byte little-endian load address followed by the bytes (the C64 disk/tape file format).
VICE label file: one label a line, `al C:1000 .name` (the monitor's `ll`/`sl` format); ACME, 64tass
and ca65 (via ld65 -Ln) all write it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from retro.errors import InputError
from retro.fileio import read_bytes, read_text

PRG_HEADER_SIZE = 2
ADDRESS_LIMIT = 0xFFFF  # the 6502's 16-bit address space


@dataclass(frozen=True)
class Program:
    code: bytes
    origin: int
    symbols: dict[str, int] = field(default_factory=dict)
    listing: str = ""
    source: str = ""
    # bare name -> its qualified candidates ("proc::loop", or "loop@$C005" where the format has no
    # scopes): a name defined twice is never resolved silently to one of them
    ambiguous: dict[str, tuple[str, ...]] = field(default_factory=dict)
    cpu: str | None = None  # the CPU the file implies ("2a03" for an iNES image), None when it does not say

    @property
    def end(self) -> int:
        """One past the last byte."""
        return self.origin + len(self.code)

    def address_of(self, label: str) -> int:
        if label in self.ambiguous:
            raise InputError(f"{self.source or 'program'}: {ambiguity_message(label, self.ambiguous[label])}")
        try:
            return self.symbols[label]
        except KeyError:
            raise InputError(f"{self.source or 'program'}: unknown label {label!r}") from None


def ambiguity_message(name: str, candidates: tuple[str, ...]) -> str:
    return f"label {name!r} is defined more than once ({', '.join(candidates)}); name one of them"


def prg_bytes(program: Program) -> bytes:
    return program.origin.to_bytes(PRG_HEADER_SIZE, "little") + program.code


def parse_prg(data: bytes, source: str = "PRG") -> Program:
    if len(data) < PRG_HEADER_SIZE:
        raise InputError(f"{source}: a PRG needs a 2-byte load address, file has {len(data)} byte(s)")
    origin = int.from_bytes(data[:PRG_HEADER_SIZE], "little")
    code = bytes(data[PRG_HEADER_SIZE:])
    if origin + len(code) > ADDRESS_LIMIT + 1:
        raise InputError(f"{source}: {len(code)} bytes at ${origin:04X} run past $FFFF")
    return Program(code=code, origin=origin, source=source)


# ACME writes `al C:c000 .name`, 64tass `al c000 .name`, ld65 (-Ln) `al 00C000 .name`.
_LABEL_LINE = re.compile(r"^al\s+(?:C:)?(?P<address>[0-9A-Fa-f]{1,6})\s+\.?(?P<name>\S+)\s*$")


def parse_vice_labels(text: str, source: str = "labels") -> dict[str, int]:
    """VICE label lines -> {name: address}; a name given twice keeps its last address."""
    symbols: dict[str, int] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith(("#", ";")):
            continue
        match = _LABEL_LINE.match(stripped)
        if not match:
            raise InputError(f"{source}:{number}: expected 'al C:ADDR .name', got {stripped[:60]!r}")
        address = int(match.group("address"), 16)
        if address > ADDRESS_LIMIT:
            raise InputError(f"{source}:{number}: address ${address:X} of {match.group('name')!r} is above $FFFF")
        symbols[match.group("name")] = address
    return symbols


def format_vice_labels(symbols: dict[str, int]) -> str:
    return "".join(f"al C:{address:04x} .{name}\n" for name, address in sorted(symbols.items(), key=lambda kv: (kv[1], kv[0])))


def load_prg_file(path: str | Path, labels: str | Path | None = None) -> Program:
    program = parse_prg(read_bytes(path, "PRG file"), source=str(path))
    symbols = parse_vice_labels(read_text(labels, "label file"), source=str(labels)) if labels else {}
    return Program(code=program.code, origin=program.origin, symbols=symbols, source=str(path))
