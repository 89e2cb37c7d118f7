"""`retro asm`: assemble an Ophis source into a PRG, and optionally a VICE label file and a listing."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.assembler import MAX_SOURCE_BYTES, assemble_file
from retro.cpu.variants import variant_named
from retro.fileio import all_or_nothing, file_option, read_bytes, write_atomic
from retro.loaders import refuse_foreign_source
from retro.program import Program, format_vice_labels, prg_bytes
import argparse
from retro.commands import options


@dataclass(frozen=True)
class Assembled:
    program: Program
    written: tuple[Path, ...]  # the PRG first, then the labels and the listing if asked for


@all_or_nothing
def asm(source: str | Path, *, output: str | Path | None = None, labels: str | Path | None = None,
        listing: str | Path | None = None, cpu: str | None = None) -> Assembled:
    """Assemble `source`; write the PRG to `output` (default: the source's name with .prg), the VICE
    labels and the listing where asked: all or none, never over a file the assembly read (docs/files.md).
    `cpu="65c02"` assembles the 65C02's opcodes (Ophis's -c) instead of the NMOS undocumented ones."""
    for option, name in (("-o", output), ("--labels", labels), ("--list", listing)):
        file_option(name, option)
    cpu = variant_named(cpu, "--cpu") if cpu else None
    data = read_bytes(source, "source file", MAX_SOURCE_BYTES)
    refuse_foreign_source(source, data)
    program = assemble_file(source, data=data, cpu=cpu)
    outputs = [(Path(output) if output is not None else Path(source).with_suffix(".prg"), prg_bytes(program),
                "PRG (-o)" if output is not None else "PRG")]
    if labels is not None:
        outputs.append((Path(labels), format_vice_labels(program.symbols), "labels (--labels)"))
    if listing is not None:
        outputs.append((Path(listing), program.listing, "listing (--list)"))
    for path, data, what in outputs:  # staged; all put in place when asm returns (all_or_nothing)
        write_atomic(path, data, what=what)
    return Assembled(program, tuple(path for path, _, _ in outputs))


def lines(result: Assembled) -> list[str]:
    program = result.program
    span = f"${program.origin:04X}-${program.end - 1:04X}" if program.code else f"${program.origin:04X}"
    return [f"{len(program.code)} bytes at {span}, {len(program.symbols)} labels -> "
            f"{', '.join(str(path) for path in result.written)}"]


# The command line: this command's options and how it runs from them.

HELP = "assemble a 6502 source (Ophis syntax) into a PRG and a VICE label file"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("source", metavar="FILE.s", help="a 6502 source in Ophis syntax")
    p.add_argument("-o", "--output", metavar="OUT.prg", help="PRG to write (default: FILE.prg)")
    p.add_argument("--labels", metavar="OUT.lbl", help="VICE label file to write")
    p.add_argument("--list", dest="listing", metavar="OUT.lst", help="listing to write")
    p.add_argument("--cpu", metavar="CPU", help="65c02: assemble the WDC 65C02's opcodes (default: the NMOS "
                                                "6502's, undocumented ones included)")


def main(args: argparse.Namespace) -> int:
    result = asm(args.source, output=args.output, labels=args.labels, listing=args.listing, cpu=args.cpu)
    options.show(lines, None, result)
    return 0
