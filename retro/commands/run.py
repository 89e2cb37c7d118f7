"""`retro run`: load a program (source, PRG, raw binary or iNES image) into a machine, with a chip
scene if one is given, call a routine and report registers, cycles, memory and raster position.
Or, for an iNES image without `--entry`, run the cartridge on a console from its reset vector for
N frames or until a condition, and report the state after the run and a test ROM's verdict
(`retro.analysis.console_run`; docs/nes.md "Running a cartridge")."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.analysis.console_run import MAX_FRAMES, ConsoleRun, ppu_registers, run_cartridge
from retro.chips.cartridge import read_nrom
from retro.chips.ines import INES_MAGIC
from retro.cpu.machine import DEFAULT_BUDGET, DEFAULT_FLAGS, JSR_CYCLES, MAX_BUDGET, CallResult, Machine
from retro.cpu.mpu import FLAG_B, FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_U, FLAG_V, FLAG_Z
from retro.cpu.variants import variant_named
from retro.errors import InputError
from retro.fileio import file_option, read_bytes
from retro.loaders import load_program
from retro.numbers import parse_int
from retro.machines import build_machine
from retro.machines.c64 import RasterBudget, call_budget
from retro.program import Program
from retro.scenes import load_scene
import argparse
from retro.commands import options

# the status flags a caller may set for the call (B and bit 5 are not flags the CPU keeps)
SETTABLE_FLAGS = {"n": FLAG_N, "v": FLAG_V, "d": FLAG_D, "i": FLAG_I, "z": FLAG_Z, "c": FLAG_C}
STATUS_BITS_HEADER = "N V - B D I Z C"  # P from bit 7 down to bit 0, as the 6502 manuals draw it


@dataclass
class RunReport:
    program: Program
    entry: int
    result: CallResult
    peeks: dict[str, list[int]]  # TARGET as the user gave it (without :N) -> byte values
    machine: Machine
    raster: RasterBudget | None  # where on the beam the call ran, with a VIC-II scene


def status_with_flags(flags: dict[str, int | str] | None) -> int:
    """The P register to enter with: the default, with each named flag (n v d i z c) set to 0 or 1."""
    p = DEFAULT_FLAGS
    for name, value in (flags or {}).items():
        bit = SETTABLE_FLAGS.get(name.lower())
        if bit is None:
            raise InputError(f"--{name}: not a settable flag (known: {', '.join(SETTABLE_FLAGS)})")
        p = p | bit if parse_int(value, field=f"--{name}", lo=0, hi=1) else p & ~bit
    return p


def _is_label(target: str) -> bool:
    """Whether --entry names a label rather than giving a number."""
    try:
        parse_int(target)
    except InputError:
        return True
    return False


def parse_assignment(text: str) -> tuple[str, list[int]]:
    """'TARGET=V' or 'TARGET=V,V,...' -> (target, bytes)."""
    target, sep, values = text.partition("=")
    if not sep or not target.strip() or not values.strip():
        raise InputError(f"--set {text!r}: expected TARGET=VALUE[,VALUE...]")
    return target.strip(), [parse_int(v, field=f"--set {target.strip()}", lo=0, hi=0xFF) for v in values.split(",")]


def parse_peek(text: str) -> tuple[str, int]:
    """'TARGET' or 'TARGET:N' -> (target, count)."""
    target, sep, count = text.rpartition(":") if ":" in text else (text, "", "1")
    if not target.strip():
        raise InputError(f"--peek {text!r}: expected TARGET[:N]")
    return target.strip(), parse_int(count, field=f"--peek {text} count", lo=1, hi=0x10000)


def _peek_counts(peeks: list[str]) -> dict[str, int]:
    """--peek arguments -> {TARGET as given: byte count}; one count per target."""
    counts: dict[str, int] = {}
    for given in peeks:
        target, count = parse_peek(given)
        if counts.get(target, count) != count:
            raise InputError(f"--peek {given!r}: {target} is already peeked with count {counts[target]}")
        counts[target] = count
    return counts


DEFAULT_FRAMES = 600  # ten seconds of NES time: every blargg ROM of the standard suites reports within it
RAM_END = 0x0800
PRG_RAM_START, PRG_RAM_END = 0x6000, 0x8000


def is_cartridge(path: str | Path) -> bool:
    """Whether the file is an iNES image (by content)."""
    return read_bytes(path, "program file")[:len(INES_MAGIC)] == INES_MAGIC


def run_console(path: str | Path, *, frames: int | str = DEFAULT_FRAMES, until: str | int | None = None,
                until_value: str | None = None, result: str | int | None = None, labels: str | Path | None = None,
                peeks: list[str] = ()) -> ConsoleRun:
    """Run the cartridge at `path` from its reset vector for `frames` frames, or until the PC reaches
    `until`, the byte `until_value` ("TARGET=V") holds its value, or the program halts; `result` is
    the address of a result byte (blargg's 2005 ROMs: $F8); `peeks` TARGET[:N] reads after the run."""
    frames = parse_int(frames, field="--frames", lo=1, hi=MAX_FRAMES)
    data = read_bytes(path, "program file")
    cartridge = read_nrom(data, str(path))
    program = load_program(path, symbols=labels)
    resolver = Machine("2a03")
    resolver.load(program)
    stop_pc = None if until is None else resolver.resolve(until, "--until")
    value = None
    if until_value is not None:
        target, values = parse_assignment(until_value)
        if len(values) != 1:
            raise InputError(f"--until-value {until_value!r}: one byte value, not {len(values)}")
        value = (resolver.resolve(target, f"--until-value {target}"), values[0])
    result_at = None if result is None else resolver.resolve(result, "--result")
    peek_counts = _peek_counts(peeks)
    for target in peek_counts:
        resolver.resolve(target, f"--peek {target}")
    report = run_cartridge(cartridge, frames=frames, until=stop_pc, until_value=value, result_at=result_at)
    report.machine.symbols.update(program.symbols)
    report.peeks = {target: report.machine.peek(target, count) for target, count in peek_counts.items()}
    return report


CONSOLE_OPTIONS = {"frames": "--frames", "until": "--until", "until_value": "--until-value", "result": "--result"}


def refuse_console_options(given: dict) -> None:
    """--frames, --until, --until-value and --result belong to a cartridge run from reset, not to a call."""
    used = [CONSOLE_OPTIONS[name] for name, value in given.items() if value is not None]
    if used:
        raise InputError(f"{', '.join(used)}: only for an iNES image run from its reset vector (without --entry)")


def run_console_or_refuse(path: str | Path, *, load=None, scene=None, trace: bool = False, cpu: str | None = None,
                          **options) -> ConsoleRun:
    """`retro run FILE` without --entry: a cartridge from reset, or a one-line error saying what is missing."""
    if not is_cartridge(path):
        raise InputError(f"--entry: required for {path} (only an iNES image runs from its reset vector)")
    for name, value in (("--load", load), ("--scene", scene), ("--trace", trace or None)):
        if value is not None:
            raise InputError(f"{name}: not for a cartridge run from reset ({path} is an iNES image run without --entry)")
    if cpu is not None and variant_named(cpu, "--cpu") != "2a03":
        raise InputError(f"--cpu {cpu}: {path} is an iNES image: a console runs it on the 2A03")
    return run_console(path, **options)


def _cpu(cpu: str | None, program, path) -> str | None:
    """--cpu, checked against the CPU the file implies (an iNES image: the 2A03)."""
    if cpu is None:
        return program.cpu
    chosen = variant_named(cpu, "--cpu")
    if program.cpu and chosen != program.cpu:
        raise InputError(f"--cpu {cpu}: {path} is a program for the {program.cpu.upper()}")
    return chosen


def run(path: str | Path, entry: str | int, *, labels: str | Path | None = None, load: int | str | None = None,
        a: int | str = 0, x: int | str = 0, y: int | str = 0, flags: dict[str, int | str] | None = None,
        sets: list[str] = (), peeks: list[str] = (), budget: int | str = DEFAULT_BUDGET,
        scene: str | Path | None = None, trace: bool = False, cpu: str | None = None) -> RunReport:
    """Call `entry` of the program at `path` (as by JSR, through its RTS). `sets` are TARGET=V[,V...]
    stores before the call, `peeks` TARGET[:N] reads after it; `scene` attaches a VIC-II or NES scene;
    `cpu` ("6510", "2a03", "65c02") is the CPU to run on (default: the file's own, else the 6510)."""
    registers = {name: parse_int(value, field=f"--{name}", lo=0, hi=0xFF) for name, value in (("a", a), ("x", x), ("y", y))}
    budget = parse_int(budget, field="--budget", lo=1, hi=MAX_BUDGET)
    status = status_with_flags(flags)
    program = load_program(path, symbols=file_option(labels, "--labels"), load=load,
                           cpu=variant_named(cpu, "--cpu") if cpu else None)
    from_binary_without_symbols = labels is None and not program.listing
    if from_binary_without_symbols and _is_label(str(entry)) and str(entry).strip() not in program.symbols:
        how = " (read as a raw binary: --load)" if load is not None else ""
        raise InputError(f"{path}{how} has no symbols: pass --labels with the symbol file your assembler wrote, "
                         f"or give --entry as an address")
    loaded_scene = None if scene is None else load_scene(scene)
    if loaded_scene is not None and program.cpu and loaded_scene.cpu_variant != program.cpu:
        raise InputError(f"--scene {scene}: a scene for the {loaded_scene.cpu_variant.upper()}, "
                         f"but {path} is a program for the {program.cpu.upper()}")
    machine = build_machine(loaded_scene, cpu=_cpu(cpu, program, path))
    machine.load(program)
    memory = dict(parse_assignment(s) for s in sets)
    for target in memory:
        machine.resolve(target, f"--set {target}")
    peek_counts = _peek_counts(peeks)
    for target in peek_counts:
        machine.resolve(target, f"--peek {target}")
    entry_address = machine.resolve(entry, "--entry")
    result = machine.call(entry_address, **registers, p=status, memory=memory, budget=budget, trace=trace)
    values = {target: machine.peek(target, count) for target, count in peek_counts.items()}
    return RunReport(program=program, entry=entry_address, result=result, peeks=values, machine=machine,
                     raster=call_budget(machine, result))


STOP_REASONS = {
    "frames": "the frame count ran out",
    "until": "the PC reached --until",
    "until-value": "the --until-value byte took its value",
    "halted": "the program halted (an instruction jumping to itself with the NMI off)",
    "verdict": "the test ROM reported its result",
    "interrupted": "interrupted (Ctrl-C)",
}


def console_json(report: ConsoleRun) -> dict:
    """The object `retro run CART.nes --json` prints: the state after the run and the verdict."""
    mpu = report.machine.mpu
    memory = report.machine.memory
    return {"entry": report.entry, "stopped": report.stopped, "frames": round(report.frames_run, 3),
            "cycles": report.cycles, "instructions": report.instructions, "halt_pc": report.halt_pc,
            "cpu": {"pc": mpu.pc, "a": mpu.a, "x": mpu.x, "y": mpu.y, "s": mpu.sp, "p": (mpu.p | FLAG_U) & ~FLAG_B},
            "ppu": ppu_registers(report.ppu),
            "ram": bytes(memory[:RAM_END]).hex(), "prg_ram": bytes(memory[PRG_RAM_START:PRG_RAM_END]).hex(),
            "peek": report.peeks, "verdict": report.verdict.as_dict() if report.verdict else None}


def console_lines(report: ConsoleRun) -> list[str]:
    mpu = report.machine.mpu
    ppu = ppu_registers(report.ppu)
    p = (mpu.p | FLAG_U) & ~FLAG_B
    out = [f"ran {report.frames_run:.2f} of {report.frames_asked} frames ({report.cycles} cycles, "
           f"{report.instructions} instructions) from the reset vector ${report.entry:04X}",
           f"stopped: {STOP_REASONS[report.stopped]}"
           + (f" at ${report.halt_pc:04X}" if report.halt_pc is not None else ""),
           f"PC=${mpu.pc:04X} A=${mpu.a:02X} X=${mpu.x:02X} Y=${mpu.y:02X} S=${mpu.sp:02X} P=${p:02X}",
           f"PPU: frame {ppu['frame']} line {ppu['line']} dot {ppu['dot']}, $2000=${ppu['ctrl']:02X} "
           f"$2001=${ppu['mask']:02X} $2002=${ppu['status']:02X}"]
    out += [f"{target}: " + " ".join(f"${v:02X}" for v in values) for target, values in report.peeks.items()]
    if report.verdict is not None:
        out.append(f"verdict: {report.verdict.summary()}")
        if report.verdict.protocol == "$6000":
            out += [f"  {line}".rstrip() for line in report.verdict.text.splitlines()]
    return out


def as_json(report: RunReport | ConsoleRun) -> dict:
    """The object `retro run --json` prints (its keys are a contract: no trace in it)."""
    if isinstance(report, ConsoleRun):
        return console_json(report)
    r = report.result
    return {"cycles": r.cycles, "instructions": r.instructions, "a": r.a, "x": r.x, "y": r.y, "s": r.s, "p": r.p,
            "peek": report.peeks, **({"raster": report.raster.as_dict()} if report.raster else {}),
            **({"notes": list(report.program.notes)} if report.program.notes else {})}


def trace_lines(report: RunReport) -> list[str]:
    """Every instruction executed (and every interrupt taken), with its cycles and the running total."""
    out = ["address  instruction    cycles  total  read       notes"]
    total = 0
    for e in report.result.trace or ():
        total += e.cycles
        notes = " ".join(n for n, on in (("taken", e.branch_taken), ("page+1", e.page_crossed)) if on)
        if e.stolen:
            notes = f"{notes} stolen {e.stolen}".strip()
        text = e.mnemonic if e.mode == "int" else report.machine.disassemble_at(e.address)
        read = f"${e.read:02X}@${e.operand:04X}" if e.read is not None else ""
        out.append(f"${e.address:04X}    {text:<14} {e.cycles:>6}  {total:>5}  {read:<10} {notes}".rstrip())
    return out


def lines(report: RunReport | ConsoleRun) -> list[str]:
    if isinstance(report, ConsoleRun):
        return console_lines(report)
    r = report.result
    out = trace_lines(report) if r.trace else []
    out += [f"A=${r.a:02X} X=${r.x:02X} Y=${r.y:02X} S=${r.s:02X} P=${r.p:02X}",
            STATUS_BITS_HEADER,
            " ".join(str(r.p >> bit & 1) for bit in range(7, -1, -1)),
            f"{r.cycles} cycles, {r.instructions} instructions (from the entry ${report.entry:04X} through its RTS; "
            f"the caller's JSR, {JSR_CYCLES} cycles, is not included)"]
    budget = report.raster
    if budget is not None:
        out.append(f"raster: line {budget.start_line} cycle {budget.start_cycle} -> line {budget.end_line} cycle "
                   f"{budget.end_cycle}, {budget.lines} lines ({budget.stolen} of the cycles stolen by the VIC-II"
                   f"{'; crosses a frame end' if budget.frames else ''})")
    out += [f"{target}: " + " ".join(f"${v:02X}" for v in values) for target, values in report.peeks.items()]
    out += [f"note: {note}" for note in report.program.notes]  # e.g. a symbol file's skipped lines
    return out


# The command line: this command's options and how it runs from them.

HELP = "call a 6502 routine in the emulator and report registers, cycles and memory"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("program", metavar="FILE.s|FILE.prg|FILE.bin|FILE.nes",
                   help="an Ophis source, a C64 .prg, a raw binary (with --load) or an iNES image (NROM)")
    p.add_argument("--labels", metavar="F", help="symbol file of a .prg, .bin or .nes, in any supported format "
                                                   "(docs/symbols.md)")
    p.add_argument("--load", metavar="ADDR", help="load address of a raw binary")
    p.add_argument("--entry", metavar="LABEL|ADDR", help="where the routine starts (called as by JSR); without it "
                   "an iNES image runs on a console from its reset vector (--frames, --until, --until-value, --result)")
    p.add_argument("--frames", metavar="N", help=f"iNES image from reset: frames to run (default {DEFAULT_FRAMES}, "
                   f"at most {MAX_FRAMES:,}); the run also stops when the program halts (JMP * with the NMI off)")
    p.add_argument("--until", metavar="LABEL|ADDR", help="iNES image from reset: stop when the PC reaches this address")
    p.add_argument("--until-value", metavar="TARGET=V", help="iNES image from reset: stop when this byte holds V")
    p.add_argument("--result", metavar="ADDR", help="iNES image from reset: a test ROM's result byte (blargg's 2005 "
                   "ROMs: $F8, 1 = passed); the $6000 protocol is read without it; exit 1 on a failed verdict")
    for register in ("a", "x", "y"):
        p.add_argument(f"--{register}", default="0", metavar="V", help=f"{register.upper()} on entry (default 0)")
    for flag in SETTABLE_FLAGS:
        p.add_argument(f"--{flag}", metavar="0|1", help=f"{flag.upper()} flag on entry")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="TARGET=V",
                   help="store bytes before the call: a label or address = V[,V...] (repeatable)")
    p.add_argument("--peek", dest="peeks", action="append", default=[], metavar="TARGET[:N]",
                   help="show N bytes (default 1) at a label or address after the call (repeatable)")
    p.add_argument("--budget", default=str(DEFAULT_BUDGET), metavar="CYCLES",
                   help=f"stop the routine after this many cycles (default {DEFAULT_BUDGET:,}, at most {MAX_BUDGET:,})")
    p.add_argument("--scene", metavar="SCENE.toml", help="attach a VIC-II or NES PPU scene to the machine")
    p.add_argument("--cpu", metavar="CPU", help="the CPU: 6510 (default), 2a03 (an iNES image's) or 65c02 (WDC)")
    output = p.add_mutually_exclusive_group()  # the JSON object's keys are fixed: no room for a trace
    output.add_argument("--trace", action="store_true", help="print every instruction executed")
    output.add_argument("--json", action="store_true", help="print one JSON object")


def main(args: argparse.Namespace) -> int:
    console = {"frames": args.frames, "until": args.until, "until_value": args.until_value, "result": args.result}
    if args.entry is None:
        report = run_console_or_refuse(args.program, labels=args.labels, peeks=args.peeks, load=args.load,
                                       scene=args.scene, trace=args.trace, cpu=args.cpu,
                                       **{k: v for k, v in console.items() if v is not None})
        options.show(lines, as_json if args.json else None, report)
        return 1 if report.verdict is not None and report.verdict.passed is False else 0
    refuse_console_options(console)
    flags = {flag: getattr(args, flag) for flag in SETTABLE_FLAGS if getattr(args, flag) is not None}
    report = run(args.program, args.entry, labels=args.labels, load=args.load, a=args.a, x=args.x, y=args.y,
                 flags=flags, sets=args.sets, peeks=args.peeks, budget=args.budget, scene=args.scene,
                 trace=args.trace, cpu=args.cpu)
    options.show(lines, as_json if args.json else None, report)
    return 0
