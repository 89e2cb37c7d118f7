"""A program file of any kind the user brings -> `Program`, recognised from its content.

- iNES or NES 2.0 image (`NES\\x1a` header, nesdev wiki "INES", "NES 2.0"): mapper 0 (NROM) only; a
  header that asks for hardware retro does not model is refused, naming the field
  (retro.chips.ines.unmodelled); 16 KiB of PRG ROM is seen at $8000 and mirrored at $C000, 32 KiB fills $8000-$FFFF; the CPU is the 2A03. The vectors
  at $FFFA/$FFFC/$FFFE are named `vector:nmi`, `vector:reset`, `vector:irq`, and `nmi`, `reset`,
  `irq` too where the symbol file does not use those names (a user's label always wins).
- Text: Ophis source, assembled; source in another assembler's syntax is refused, naming it.
- A load address given: a raw binary placed there.
- A file named `.prg`: a 2-byte little-endian load address, then the bytes (its content cannot be
  told from a raw binary's, so the name decides; any other binary needs a load address).
"""

from __future__ import annotations

import re
from pathlib import Path

from retro.chips.cartridge import PRG_START
from retro.chips.ines import INES_MAGIC, nrom_prg
from retro.assembler import MAX_SOURCE_BYTES, assemble_file
from retro.errors import InputError
from retro.fileio import read_bytes
from retro.loaders.symbols import read_symbol_file, symbol_tables
from retro.numbers import parse_address
from retro.program import ADDRESS_LIMIT, Program, parse_prg

NES_CPU = "2a03"
# 6502 hardware vectors (MOS datasheet): the CPU reads the handler's address from these words
CPU_VECTORS = {"nmi": 0xFFFA, "reset": 0xFFFC, "irq": 0xFFFE}
VECTOR_PREFIX = "vector:"  # not a label character in any supported assembler: never clashes
PRG_SUFFIX = ".prg"
# the largest program file is an Ophis source (a PRG, a raw binary or an NROM image is under 64 KiB)
MAX_PROGRAM_BYTES = MAX_SOURCE_BYTES

_BINARY_CONTROL = re.compile(rb"[\x00-\x08\x0e-\x1a\x1c-\x1f]")  # not in any text file (ESC aside)


def is_text(data: bytes) -> bool:
    if _BINARY_CONTROL.search(data):
        return False
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


# ---- foreign assembler syntax -----------------------------------------------------------------

# Directives Ophis does not have, each distinctive of one assembler (their manuals). Checked per
# line with comments removed; the first line with a clue names the assembler.
_LABEL_COLUMN = r"^(?:[A-Za-z_@][\w.@]*:?)?\s+"  # a label in column 0 (not an Ophis `.alias`), then the directive
_FOREIGN_SYNTAX: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("ACME", re.compile(_LABEL_COLUMN + r"!(?:byte|by|8|word|wo|16|zone|zn|to|cpu|source|src|binary|bin|fill|fi|"
                        r"text|tx|pet|scr|pseudopc|macro|if|ifdef|for|set|align|initmem)\b|^!", re.I)),
    ("ca65", re.compile(r"^\s*(?:\S+:\s*)?\.(?:proc|endproc|segment|endscope|res|export|exportzp|import|importzp|"
                        r"zeropage|setcpu|endmacro|addr|repeat|endrep|autoimport|feature)\b", re.I)),
    ("64tass", re.compile(_LABEL_COLUMN + r"\.(?:block|bend|pend|logical|here|cpu|section|send|dsection|null|"
                          r"shift|rta|binclude|enc)\b", re.I)),
    ("Kick Assembler", re.compile(r"^\s*(?:\.pc\s*=|\*\s*=\s*\S+\s+\"|BasicUpstart2?\b|\.(?:const|var|label|"
                                  r"namespace|filenamespace|function|eval|print|encoding|import\s+source)\b)", re.I)),
    ("xa", re.compile(_LABEL_COLUMN + r"\.(?:\(|\)|byt|dsb|asc|aasc)(?:\s|$)", re.I)),
    ("DASM", re.compile(r"^\s*processor\s|" + _LABEL_COLUMN + r"(?:org|seg(?:\.u)?|subroutine|dc\.[bwl]|ds\.[bwl]|"
                        r"ifconst|ifnconst)\b", re.I)),
)
# `* = $c000` sets the origin in ACME, 64tass and xa (Ophis writes `.org`): a clue only when no
# directive above names the assembler
_STAR_ORIGIN = ("ACME, 64tass or xa", re.compile(r"^\s*\*\s*="))
_COMMENT = re.compile(r";.*$")


def foreign_assembler(text: str) -> str | None:
    """The assembler whose syntax this (non-Ophis) source is written in, or None if it may be Ophis."""
    code_lines = [code for code in (_COMMENT.sub("", line) for line in text.splitlines()) if code.strip()]
    for patterns in (_FOREIGN_SYNTAX, (_STAR_ORIGIN,)):
        for code in code_lines:
            for assembler, pattern in patterns:
                if pattern.search(code):
                    return assembler
    return None


def refuse_foreign_source(path: str | Path, data: bytes) -> str:
    """The text of an Ophis source, or an error naming the file and what it looks like instead."""
    advice = "assemble it with your assembler and pass the .prg and --labels"
    if not is_text(data):
        raise InputError(f"{path}: not Ophis source (a binary file)")
    text = data.decode("utf-8")
    assembler = foreign_assembler(text)
    if assembler:
        raise InputError(f"{path}: not Ophis source (looks like {assembler}); {advice}")
    return text


# ---- binaries --------------------------------------------------------------------------------

def _nes_program(data: bytes, source: str) -> tuple[Program, dict[str, int]]:
    """iNES image -> (Program of the CPU's view of PRG ROM, {vector name: handler address})."""
    _, image = nrom_prg(data, source)
    program = Program(code=bytes(image), origin=PRG_START, source=source, cpu=NES_CPU)
    vectors = {name: int.from_bytes(image[at - PRG_START:at - PRG_START + 2], "little")
               for name, at in CPU_VECTORS.items()}
    return program, vectors


def _raw_program(data: bytes, load: int | str, source: str) -> Program:
    origin = parse_address(load, field="--load")
    if not data:
        raise InputError(f"{source}: empty file")
    if origin + len(data) > ADDRESS_LIMIT + 1:
        raise InputError(f"{source}: {len(data)} bytes at ${origin:04X} run past ${ADDRESS_LIMIT:04X}")
    return Program(code=bytes(data), origin=origin, source=source)


def _with_symbols(program: Program, symbols: str | Path | None, vectors: dict[str, int]) -> Program:
    symbol_file = read_symbol_file(symbols) if symbols else None
    table, ambiguous = symbol_tables(symbol_file.symbols) if symbol_file else ({}, {})
    for name, address in vectors.items():
        table[VECTOR_PREFIX + name] = address
        if name not in table and name not in ambiguous:
            table[name] = address
    return Program(code=program.code, origin=program.origin, symbols=table, ambiguous=ambiguous,
                   source=program.source, cpu=program.cpu,
                   notes=(symbol_file.note,) if symbol_file and symbol_file.note else ())


def load_program(path: str | Path, *, symbols: str | Path | None = None, load: int | str | None = None,
                 cpu: str | None = None) -> Program:
    """Any program file -> Program; `symbols` is a symbol file in any known format, `load` the
    address of a raw binary, `cpu` the CPU a source is assembled for ("65c02": its opcodes)."""
    source = str(path)
    data = read_bytes(path, "program file", MAX_PROGRAM_BYTES)
    if data[:len(INES_MAGIC)] == INES_MAGIC:
        if load is not None:
            raise InputError(f"--load: {source} is an iNES image, which says where its ROM goes")
        program, vectors = _nes_program(data, source)
        return _with_symbols(program, symbols, vectors)
    if load is not None:
        return _with_symbols(_raw_program(data, load, source), symbols, {})
    if Path(source).suffix.lower() == PRG_SUFFIX:  # a PRG's content cannot be told from a raw binary's
        return _with_symbols(parse_prg(data, source=source), symbols, {})
    if not data.strip():
        raise InputError(f"{source}: empty file")
    if is_text(data):
        refuse_foreign_source(path, data)
        if symbols:
            raise InputError(f"{symbols}: a symbol file (--labels) goes with a .prg, a raw binary or a .nes "
                             f"image; a source's labels come from the assembler")
        return assemble_file(path, data=data, cpu=cpu)
    raise InputError(f"{source}: a binary file without a load address: pass --load ADDR for a raw binary, "
                     f"or name a C64 program .prg (2-byte load address first)")
