"""`retro run FILE.s|FILE.prg|FILE.bin|FILE.nes --entry LABEL|ADDR [--labels F] [--load ADDR] [...] [--json]`"""

from __future__ import annotations

import argparse
import json

from retro.app.run import SETTABLE_FLAGS, run_routine
from retro.cpu.machine import DEFAULT_BUDGET, MAX_BUDGET, JSR_CYCLES
from retro.machines.c64 import call_budget
from retro.numbers import parse_int

# P from bit 7 down to bit 0, as the 6502 manuals draw it
STATUS_BITS_HEADER = "N V - B D I Z C"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("run", help="call a 6502 routine in the emulator and report registers, cycles and memory")
    p.add_argument("program", metavar="FILE.s|FILE.prg|FILE.bin|FILE.nes",
                   help="an Ophis source, a C64 .prg, a raw binary (with --load) or an iNES image (NROM)")
    p.add_argument("--labels", metavar="F", help="symbol file of a .prg, .bin or .nes, in any supported format "
                                                   "(docs/symbols.md)")
    p.add_argument("--load", metavar="ADDR", help="load address of a raw binary")
    p.add_argument("--entry", required=True, metavar="LABEL|ADDR", help="where the routine starts (called as by JSR)")
    p.add_argument("--a", default="0", metavar="V", help="A on entry (default 0)")
    p.add_argument("--x", default="0", metavar="V", help="X on entry (default 0)")
    p.add_argument("--y", default="0", metavar="V", help="Y on entry (default 0)")
    for flag in SETTABLE_FLAGS:
        p.add_argument(f"--{flag}", metavar="0|1", help=f"{flag.upper()} flag on entry")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="TARGET=V",
                   help="store bytes before the call: a label or address = V[,V...] (repeatable)")
    p.add_argument("--peek", dest="peeks", action="append", default=[], metavar="TARGET[:N]",
                   help="show N bytes (default 1) at a label or address after the call (repeatable)")
    p.add_argument("--budget", default=str(DEFAULT_BUDGET), metavar="CYCLES",
                   help=f"stop the routine after this many cycles (default {DEFAULT_BUDGET:,}, at most {MAX_BUDGET:,})")
    p.add_argument("--scene", metavar="SCENE.toml", help="attach a VIC-II or NES PPU scene to the machine")
    output = p.add_mutually_exclusive_group()  # the JSON object's keys are fixed: no room for a trace
    output.add_argument("--trace", action="store_true", help="print every instruction executed")
    output.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_run)


def cmd_run(args: argparse.Namespace) -> int:
    flags = {flag: parse_int(getattr(args, flag), field=f"--{flag}", lo=0, hi=1)
             for flag in SETTABLE_FLAGS if getattr(args, flag) is not None}
    report = run_routine(
        args.program, args.entry, labels=args.labels, load=args.load,
        a=parse_int(args.a, field="--a", lo=0, hi=0xFF), x=parse_int(args.x, field="--x", lo=0, hi=0xFF),
        y=parse_int(args.y, field="--y", lo=0, hi=0xFF), flags=flags, sets=args.sets, peeks=args.peeks,
        budget=parse_int(args.budget, field="--budget", lo=1, hi=MAX_BUDGET), scene=args.scene, trace=args.trace)
    r = report.result
    if args.json:
        budget = call_budget(report.machine, r)
        print(json.dumps({"cycles": r.cycles, "instructions": r.instructions, "a": r.a, "x": r.x, "y": r.y,
                          "s": r.s, "p": r.p, "peek": report.peeks,
                          **({"raster": budget.as_dict()} if budget else {})}))
        return 0
    if r.trace:
        print("address  instruction    cycles  total  read       notes")
        total = 0
        for e in r.trace:
            total += e.cycles
            notes = " ".join(n for n, on in (("taken", e.branch_taken), ("page+1", e.page_crossed)) if on)
            if e.stolen:
                notes = f"{notes} stolen {e.stolen}".strip()
            text = e.mnemonic if e.mode == "int" else report.machine.disassemble_at(e.address)
            read = f"${e.read:02X}@${e.operand:04X}" if e.read is not None else ""
            print(f"${e.address:04X}    {text:<14} {e.cycles:>6}  {total:>5}  {read:<10} {notes}".rstrip())
    print(f"A=${r.a:02X} X=${r.x:02X} Y=${r.y:02X} S=${r.s:02X} P=${r.p:02X}")
    print(STATUS_BITS_HEADER)
    print(" ".join(str(r.p >> bit & 1) for bit in range(7, -1, -1)))
    print(f"{r.cycles} cycles, {r.instructions} instructions "
          f"(from the entry ${report.entry:04X} through its RTS; the caller's JSR, {JSR_CYCLES} cycles, is not included)")
    budget = call_budget(report.machine, r)
    if budget is not None:
        print(f"raster: line {budget.start_line} cycle {budget.start_cycle} -> line {budget.end_line} cycle "
              f"{budget.end_cycle}, {budget.lines} lines ({budget.stolen} of the cycles stolen by the VIC-II"
              f"{'; crosses a frame end' if budget.frames else ''})")
    for target, values in report.peeks.items():
        print(f"{target}: " + " ".join(f"${v:02X}" for v in values))
    return 0
