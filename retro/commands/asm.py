"""`retro asm`: assemble an Ophis source into a PRG, and optionally a VICE label file and a listing."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.assembler import MAX_SOURCE_BYTES, assemble_file
from retro.fileio import file_option, read_bytes, write_all_atomic
from retro.loaders import refuse_foreign_source
from retro.program import Program, format_vice_labels, prg_bytes


@dataclass(frozen=True)
class Assembled:
    program: Program
    written: tuple[Path, ...]  # the PRG first, then the labels and the listing if asked for


def asm(source: str | Path, *, output: str | Path | None = None, labels: str | Path | None = None,
        listing: str | Path | None = None) -> Assembled:
    """Assemble `source`; write the PRG to `output` (default: the source's name with .prg), the VICE
    labels and the listing where asked. All files are written or none, never over the source."""
    for option, name in (("-o", output), ("--labels", labels), ("--list", listing)):
        file_option(name, option)
    data = read_bytes(source, "source file", MAX_SOURCE_BYTES)
    refuse_foreign_source(source, data)
    program = assemble_file(source, data=data)
    outputs = {Path(output) if output is not None else Path(source).with_suffix(".prg"): prg_bytes(program)}
    if labels is not None:
        outputs[Path(labels)] = format_vice_labels(program.symbols)
    if listing is not None:
        outputs[Path(listing)] = program.listing
    write_all_atomic(outputs, inputs=[source])
    return Assembled(program, tuple(outputs))


def lines(result: Assembled) -> list[str]:
    program = result.program
    span = f"${program.origin:04X}-${program.end - 1:04X}" if program.code else f"${program.origin:04X}"
    return [f"{len(program.code)} bytes at {span}, {len(program.symbols)} labels -> "
            f"{', '.join(str(path) for path in result.written)}"]
