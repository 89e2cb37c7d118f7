"""A loaded 6502 program (bytes at an origin, with symbols), and the PRG / VICE label formats.

PRG: a 2-byte little-endian load address followed by the bytes (the C64 disk/tape file format).
VICE label file: one label a line, `al C:1000 .name` (the monitor's `ll`/`sl` format), as `retro asm`
writes it; reading it and every other assembler's symbol file is retro.loaders.symbols' job.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from retro.errors import InputError

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
    notes: tuple[str, ...] = ()  # what loading it left out, one line each (a symbol file's skipped lines)

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


def format_vice_labels(symbols: dict[str, int]) -> str:
    return "".join(f"al C:{address:04x} .{name}\n" for name, address in sorted(symbols.items(), key=lambda kv: (kv[1], kv[0])))
