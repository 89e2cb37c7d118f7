"""`retro asm FILE.s [-o OUT.prg] [--labels OUT.lbl] [--list OUT.lst]`"""

from __future__ import annotations

import argparse
from pathlib import Path

from retro.assembler import assemble_file
from retro.fileio import read_bytes, write_all_atomic
from retro.loaders import refuse_foreign_source
from retro.program import format_vice_labels, prg_bytes


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("asm", help="assemble a 6502 source (Ophis syntax) into a PRG and a VICE label file")
    p.add_argument("source", metavar="FILE.s", help="a 6502 source in Ophis syntax")
    p.add_argument("-o", "--output", metavar="OUT.prg", help="PRG to write (default: FILE.prg)")
    p.add_argument("--labels", metavar="OUT.lbl", help="VICE label file to write")
    p.add_argument("--list", dest="listing", metavar="OUT.lst", help="listing to write")
    p.set_defaults(func=run_asm)


def run_asm(args: argparse.Namespace) -> int:
    data = read_bytes(args.source, "source file")  # once: the source may be a FIFO
    refuse_foreign_source(args.source, data)
    program = assemble_file(args.source, data=data)
    output = Path(args.output) if args.output else Path(args.source).with_suffix(".prg")
    outputs = {output: prg_bytes(program)}
    if args.labels:
        outputs[Path(args.labels)] = format_vice_labels(program.symbols)
    if args.listing:
        outputs[Path(args.listing)] = program.listing
    write_all_atomic(outputs, inputs=[args.source])
    written = [str(path) for path in outputs]
    span = f"${program.origin:04X}-${program.end - 1:04X}" if program.code else f"${program.origin:04X}"
    print(f"{len(program.code)} bytes at {span}, {len(program.symbols)} labels -> {', '.join(written)}")
    return 0
