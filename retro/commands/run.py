"""`retro run`: load a program (source, PRG, raw binary or iNES image) into a machine, with a chip
scene if one is given, call a routine and report registers, cycles, memory and raster position.
Or run a whole program as the machine would, for N frames or until a condition, and report the
state after the run: an iNES image without `--entry` on a console from its reset vector, with a test
ROM's verdict (`retro.analysis.console_run`; docs/nes.md "Running a cartridge"); any other program
on a C64 from its BASIC SYS line, or from `--entry` when --frames, --until or --until-value is given
(`retro.analysis.c64_run`; docs/vic.md "Running a C64 program")."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.analysis.c64_run import DEFAULT_C64_FRAMES, RETURNED, C64Run, run_c64, vic_registers
from retro.analysis.console_run import DEFAULT_FRAMES, MAX_FRAMES, ConsoleRun, ppu_registers, run_cartridge
from retro.chips.cartridge import read_nrom
from retro.chips.ines import INES_MAGIC
from retro.cpu.machine import DEFAULT_BUDGET, DEFAULT_FLAGS, JSR_CYCLES, MAX_BUDGET, MAX_TRACE, CallResult, Machine
from retro.cpu.mpu import FLAG_B, FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_U, FLAG_V, FLAG_Z
from retro.cpu.variants import variant_named
from retro.errors import InputError
from retro.fileio import file_option, read_bytes
from retro.loaders import load_program
from retro.loaders.basic_stub import sys_line
from retro.numbers import parse_int
from retro.machines.c64 import RasterBudget, call_budget, vic_of
from retro.machines.nes import ppu_of, vblank_budget
from retro.program import Program
from retro.scenes import load_scene
from retro.scenes.vic import VicScene
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
    tracer: object = None  # with --trace-json or --watch: the retro.analysis.trace.Tracer of the call
    vblank: dict | None = None  # with a NES scene: the call's vblank budget (retro.machines.nes.vblank_budget)

    def _repr_html_(self) -> str:  # in a notebook: the report, the trace listing first when traced
        return options.pre_html(lines(self))


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


RAM_END = 0x0800
PRG_RAM_START, PRG_RAM_END = 0x6000, 0x8000


def is_cartridge(path: str | Path) -> bool:
    """Whether the file is an iNES image (by content)."""
    return read_bytes(path, "program file")[:len(INES_MAGIC)] == INES_MAGIC


def _stop_conditions(resolver: Machine, until, until_value) -> tuple[int | None, tuple[int, int] | None]:
    """--until and --until-value resolved against the program's symbols."""
    stop_pc = None if until is None else resolver.resolve(until, "--until")
    value = None
    if until_value is not None:
        target, values = parse_assignment(until_value)
        if len(values) != 1:
            raise InputError(f"--until-value {until_value!r}: one byte value, not {len(values)}")
        value = (resolver.resolve(target, f"--until-value {target}"), values[0])
    return stop_pc, value


def _checked_peeks(resolver: Machine, peeks: list[str]) -> dict[str, int]:
    peek_counts = _peek_counts(peeks)
    for target in peek_counts:
        resolver.resolve(target, f"--peek {target}")
    return peek_counts


def run_console(path: str | Path, *, frames: int | str = DEFAULT_FRAMES, until: str | int | None = None,
                until_value: str | None = None, result: str | int | None = None, labels: str | Path | None = None,
                peeks: list[str] = (), wrap=None) -> ConsoleRun:
    """Run the cartridge at `path` from its reset vector for `frames` frames, or until the PC reaches
    `until`, the byte `until_value` ("TARGET=V") holds its value, or the program halts; `result` is
    the address of a result byte (blargg's 2005 ROMs: $F8); `peeks` TARGET[:N] reads after the run."""
    frames = parse_int(frames, field="--frames", lo=1, hi=MAX_FRAMES)
    data = read_bytes(path, "program file")
    cartridge = read_nrom(data, str(path))
    program = load_program(path, symbols=labels)
    resolver = Machine("2a03")
    resolver.load(program)
    stop_pc, value = _stop_conditions(resolver, until, until_value)
    result_at = None if result is None else resolver.resolve(result, "--result")
    peek_counts = _checked_peeks(resolver, peeks)
    report = run_cartridge(cartridge, frames=frames, until=stop_pc, until_value=value, result_at=result_at, wrap=wrap)
    report.machine.symbols.update(program.symbols)
    report.peeks = {target: report.machine.peek(target, count) for target, count in peek_counts.items()}
    return report


def run_c64_program(path: str | Path, *, entry: str | int | None = None, frames: int | str = DEFAULT_C64_FRAMES,
                    until: str | int | None = None, until_value: str | None = None,
                    labels: str | Path | None = None, load: int | str | None = None, scene: str | Path | None = None,
                    peeks: list[str] = (), cpu: str | None = None, wrap=None, result: str | int | None = None) -> C64Run:
    """Run the program at `path` on a C64 from its BASIC SYS line (or `entry`) for `frames` frames or
    until a condition (as `run_console`), with `scene`'s VIC-II if given; `result`: a test program's
    result address (VICE's testbench: $D7FF), the run stops at its first write."""
    frames = parse_int(frames, field="--frames", lo=1, hi=MAX_FRAMES)
    if cpu is not None and variant_named(cpu, "--cpu") != "6510":
        raise InputError(f"--cpu {cpu}: a C64 program runs on the 6510")
    program = load_program(path, symbols=file_option(labels, "--labels"), load=load)
    if program.cpu and program.cpu != "6510":
        raise InputError(f"{path}: a program for the {program.cpu.upper()}, not a C64 program")
    loaded_scene = None if scene is None else load_scene(scene)
    if loaded_scene is not None and not isinstance(loaded_scene, VicScene):
        raise InputError(f"--scene {scene}: a C64 program runs with a VIC-II scene (chip = \"vic-ii\")")
    resolver = Machine("6510")
    resolver.load(program)
    stop_pc, value = _stop_conditions(resolver, until, until_value)
    peek_counts = _checked_peeks(resolver, peeks)
    result_at = None if result is None else resolver.resolve(result, "--result")
    if entry is None:
        basic = sys_line(program)
        start, line, notes = basic.address, basic.line_number, basic.notes
    else:
        start, line, notes = resolver.resolve(entry, "--entry"), None, ()
    report = run_c64(program, start, frames=frames, scene=loaded_scene, until=stop_pc, until_value=value,
                     sys_line=line, notes=notes + tuple(program.notes), wrap=wrap, result_at=result_at)
    report.peeks = {target: report.machine.peek(target, count) for target, count in peek_counts.items()}
    return report


CONSOLE_OPTIONS = {"frames": "--frames", "until": "--until", "until_value": "--until-value", "result": "--result"}
PROGRAM_RUN_OPTIONS = ("frames", "until", "until_value")  # with --entry: a C64 program run from there


def wants_program_run(path: str | Path, given: dict) -> bool:
    """Whether `retro run FILE --entry E` with these options runs a program from E rather than
    calling E: a program that is not an iNES image, with --frames, --until or --until-value."""
    return any(given.get(name) is not None for name in PROGRAM_RUN_OPTIONS) and not is_cartridge(path)


def refuse_console_options(given: dict) -> None:
    """--frames, --until, --until-value and --result belong to a program run, not to a call."""
    used = [CONSOLE_OPTIONS[name] for name, value in given.items() if value is not None]
    if used:
        raise InputError(f"{', '.join(used)}: only for a program run (an iNES image from its reset vector, "
                         f"a C64 program from its SYS line or --entry), not for a call")


def _range(text: str | None, field: str, hi: int, resolve=None) -> tuple[int, int] | None:
    """'LOW-HIGH' -> (low, high), each a number in 0..hi (or, with `resolve`, a label or address)."""
    if text is None:
        return None
    low, dash, high = str(text).partition("-")
    if not dash:
        raise InputError(f"{field} {text!r}: expected LOW-HIGH")
    if resolve is not None:
        first, last = resolve(low.strip(), field), resolve(high.strip(), field)
    else:
        first, last = parse_int(low, field=field, lo=0, hi=hi), parse_int(high, field=field, lo=0, hi=hi)
    if last < first:
        raise InputError(f"{field} {text!r}: the range ends before it starts")
    return first, last


def trace_wrapper(path, *, trace: bool, trace_json: bool, trace_limit, trace_cycles, trace_pc, watches: list[str],
                  labels=None, load=None):
    """The `wrap` of a program run that traces it and/or watches addresses (retro.analysis.trace), or
    None without --trace/--trace-json/--watch; every option checked before the run."""
    if not (trace or trace_json or watches):
        if any(v is not None for v in (trace_limit, trace_cycles, trace_pc)):
            raise InputError("--trace-limit, --trace-cycles, --trace-pc: they bound a --trace or --trace-json")
        return None
    from retro.analysis.trace import MAX_TRACE_LIMIT, TraceBounds, Tracer, parse_watch, ppu_position, vic_position
    from retro.machines.nes import ppu_of

    resolver = Machine("6510")
    resolver.load(load_program(path, symbols=file_option(labels, "--labels"), load=load))
    bounds = None
    if trace or trace_json:
        cycles = _range(trace_cycles, "--trace-cycles", MAX_BUDGET * 100)
        pcs = _range(trace_pc, "--trace-pc", 0xFFFF, resolver.resolve) or (0, 0xFFFF)
        limit = None if trace_limit is None else parse_int(trace_limit, field="--trace-limit", lo=1, hi=MAX_TRACE_LIMIT)
        bounds = TraceBounds(limit, *(cycles or (None, None)), *pcs)
        bounds.check()
    parsed = tuple(parse_watch(w, resolver.resolve) for w in watches)
    made = []

    def wrap(machine, inner):
        vic, ppu = vic_of(machine), ppu_of(machine)
        position = vic_position(vic) if vic is not None else ppu_position(ppu) if ppu is not None else None
        made.append(Tracer(machine, bounds=bounds, watches=parsed, position=position, inner=inner))
        return made[-1]
    wrap.made = made
    return wrap


def run_console_or_refuse(path: str | Path, *, load=None, scene=None, trace: bool = False, cpu: str | None = None,
                          entry: str | int | None = None, trace_json: bool = False, trace_limit=None,
                          trace_cycles=None, trace_pc=None, watches: list[str] = (), **options) -> ConsoleRun | C64Run:
    """`retro run FILE` as a program run: a cartridge from reset, or a C64 program from its SYS line
    or `entry`; or a one-line error saying what does not fit. `trace`/`trace_json` (bounded by
    `trace_limit`, `trace_cycles` "FROM-TO", `trace_pc` "LOW-HIGH") and `watches` observe the run."""
    wrap = trace_wrapper(path, trace=trace, trace_json=trace_json, trace_limit=trace_limit, trace_cycles=trace_cycles,
                         trace_pc=trace_pc, watches=list(watches), labels=options.get("labels"), load=load)
    if not is_cartridge(path):
        report = run_c64_program(path, entry=entry, load=load, scene=scene, cpu=cpu, wrap=wrap, **options)
    else:
        for name, value in (("--load", load), ("--scene", scene), ("--entry", entry)):
            if value is not None:
                raise InputError(f"{name}: not for a cartridge run from reset ({path} is an iNES image run without "
                                 f"--entry)")
        if cpu is not None and variant_named(cpu, "--cpu") != "2a03":
            raise InputError(f"--cpu {cpu}: {path} is an iNES image: a console runs it on the 2A03")
        report = run_console(path, wrap=wrap, **options)
    if wrap is not None:
        report.tracer = wrap.made[0]
    return report


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
        scene: str | Path | None = None, trace: bool = False, cpu: str | None = None, wrap=None,
        in_nmi: bool = False, at_line: int | str | None = None, at_cycle: int | str | None = None,
        at_dot: int | str | None = None) -> RunReport:
    """Call `entry` of the program at `path` (as by JSR, through its RTS). `sets` are TARGET=V[,V...]
    stores before the call, `peeks` TARGET[:N] reads after it; `scene` attaches a VIC-II or NES scene,
    the call entered at `at_line`/`at_cycle` (VIC-II) or `at_line`/`at_dot` or `in_nmi` (NES);
    `cpu` ("6510", "2a03", "65c02") is the CPU to run on (default: the file's own, else the 6510)."""
    registers = {name: parse_int(value, field=f"--{name}", lo=0, hi=0xFF) for name, value in (("a", a), ("x", x), ("y", y))}
    budget = parse_int(budget, field="--budget", lo=1, hi=MAX_BUDGET)
    status = status_with_flags(flags)
    program = _call_program(path, entry, labels, load, cpu)
    machine = _call_machine(path, program, options.call_start(scene, at_line, at_cycle, at_dot, in_nmi), cpu)
    memory = dict(parse_assignment(s) for s in sets)
    for target in memory:
        machine.resolve(target, f"--set {target}")
    peek_counts = _checked_peeks(machine, peeks)
    entry_address = machine.resolve(entry, "--entry")
    observer = None if wrap is None else wrap(machine, None)  # --trace-json / --watch (retro.analysis.trace)
    ppu = ppu_of(machine)
    start, dma_before = machine.cycle, ppu.dma_stalled if ppu is not None else 0
    result = machine.call(entry_address, **registers, p=status, memory=memory, budget=budget, trace=trace,
                          observer=observer)
    vblank = vblank_budget(machine, start, result.cycles, dma_before) if ppu is not None else None
    values = {target: machine.peek(target, count) for target, count in peek_counts.items()}
    return RunReport(program=program, entry=entry_address, result=result, peeks=values, machine=machine,
                     raster=call_budget(machine, result), vblank=vblank)


def _call_program(path: str | Path, entry: str | int, labels, load, cpu: str | None) -> Program:
    """The program a call runs; an entry given as a label needs symbols (a raw binary has none)."""
    program = load_program(path, symbols=file_option(labels, "--labels"), load=load,
                           cpu=variant_named(cpu, "--cpu") if cpu else None)
    from_binary_without_symbols = labels is None and not program.listing
    if from_binary_without_symbols and _is_label(str(entry)) and str(entry).strip() not in program.symbols:
        how = " (read as a raw binary: --load)" if load is not None else ""
        raise InputError(f"{path}{how} has no symbols: pass --labels with the symbol file your assembler wrote, "
                         f"or give --entry as an address")
    return program


def _call_machine(path: str | Path, program: Program, where, cpu: str | None) -> Machine:
    """The machine a call runs on (with the scene's chip where `where` (options.call_start) puts the
    call, for the program's CPU), the program loaded."""
    scene_cpu = None if where is None else where.scene.cpu_variant
    if scene_cpu is not None and program.cpu and scene_cpu != program.cpu:
        raise InputError(f"--scene {where.scene.source}: a scene for the {scene_cpu.upper()}, "
                         f"but {path} is a program for the {program.cpu.upper()}")
    machine = options.call_machine(where, _cpu(cpu, program, path))
    machine.load(program)
    return machine


STOP_REASONS = {
    "frames": "the frame count ran out",
    "until": "the PC reached --until",
    "until-value": "the --until-value byte took its value",
    "halted": "the program halted (an instruction jumping to itself with no interrupt to come)",
    "verdict": "the test ROM reported its result",
    RETURNED: "the program returned (the RTS from the code SYS called)",
    "interrupted": "interrupted (Ctrl-C)",
}


def console_json(report: ConsoleRun) -> dict:
    """The object `retro run CART.nes --json` prints: the state after the run and the verdict."""
    mpu = report.machine.mpu
    memory = report.machine.memory
    return {"entry": report.entry, "stopped": report.stopped, "frames": round(report.frames_run, 3),
            "cycles": report.cycles, "instructions": report.instructions, "halt_pc": report.halt_pc,
            "cpu": _cpu_state(mpu), "ppu": ppu_registers(report.ppu),
            "ram": bytes(memory[:RAM_END]).hex(), "prg_ram": bytes(memory[PRG_RAM_START:PRG_RAM_END]).hex(),
            "peek": report.peeks, "verdict": report.verdict.as_dict() if report.verdict else None,
            **_watch_json(report)}


def _watch_json(report) -> dict:
    """With --watch: the hits (and whether there were more than were kept)."""
    tracer = report.tracer
    if tracer is None or not tracer.watches:
        return {}
    return {"watch_hits": tracer.hits, "watch_hits_cut": tracer.hits_cut}


def program_trace_lines(report, as_json_lines: bool) -> list[str]:
    """A program run's trace: text lines, or one JSON object per step."""
    import json

    from retro.analysis.trace import entry_text

    tracer = report.tracer
    if as_json_lines:
        out = [json.dumps(e) for e in tracer.entries]
    else:
        out = [entry_text(e, "") for e in tracer.entries]
    if tracer.cut:
        cut = f"the trace reached its limit of {tracer.bounds.limit:,} steps; the run went on untraced"
        out.append(json.dumps({"note": cut}) if as_json_lines else f"... {cut}")
    return out


def watch_lines(report) -> list[str]:
    from retro.analysis.trace import hit_text

    tracer = report.tracer
    if tracer is None or not tracer.watches:
        return []
    unit = "line" if vic_of(report.machine) is not None else "scanline"
    out = [hit_text(h, unit) for h in tracer.hits] or ["watch: no hit"]
    if tracer.hits_cut:
        out.append("watch: more hits than were kept")
    return out


def _cpu_state(mpu) -> dict:
    return {"pc": mpu.pc, "a": mpu.a, "x": mpu.x, "y": mpu.y, "s": mpu.sp, "p": (mpu.p | FLAG_U) & ~FLAG_B}


def c64_json(report: C64Run) -> dict:
    """The object `retro run PROG.prg --json` prints: the state after the run (all 64 KiB of RAM as hex)."""
    return {"entry": report.entry, "sys_line": report.sys_line, "stopped": report.stopped,
            "frames": round(report.frames_run, 3), "cycles": report.cycles, "instructions": report.instructions,
            "halt_pc": report.halt_pc, "cpu": _cpu_state(report.machine.mpu), "vic": vic_registers(report.vic),
            "ram": bytes(report.machine.memory).hex(), "peek": report.peeks, "notes": list(report.notes),
            "verdict": report.verdict.as_dict() if report.verdict else None, "printed": report.printed,
            **_watch_json(report)}


def _frames_run_lines(report: C64Run | ConsoleRun, ran: str, chip: str) -> list[str]:
    """What a program run of either machine prints: how far it ran, why it stopped, the CPU's
    registers, the chip's line `chip`, and the bytes peeked."""
    r = _cpu_state(report.machine.mpu)
    return ([f"ran {report.frames_run:.2f} of {report.frames_asked} frames ({report.cycles} cycles, {ran}",
             f"stopped: {STOP_REASONS[report.stopped]}"
             + (f" at ${report.halt_pc:04X}" if report.halt_pc is not None else ""),
             f"PC=${r['pc']:04X} A=${r['a']:02X} X=${r['x']:02X} Y=${r['y']:02X} S=${r['s']:02X} P=${r['p']:02X}",
             chip]
            + [f"{target}: " + " ".join(f"${v:02X}" for v in values) for target, values in report.peeks.items()])


def c64_lines(report: C64Run) -> list[str]:
    vic = vic_registers(report.vic)
    start = (f"the SYS of BASIC line {report.sys_line}, ${report.entry:04X}" if report.sys_line is not None
             else f"${report.entry:04X}")
    out = _frames_run_lines(
        report, f"{report.instructions} instructions, {report.machine.mpu.stolen} stolen by the VIC-II) from {start}",
        f"VIC-II: frame {vic['frame']} line {vic['line']} cycle {vic['cycle']}, $D011=${report.vic.peek(0xD011):02X} "
        f"$D019=${vic['d019']:02X} $D01A=${report.vic.peek(0xD01A):02X} $D01E=${vic['d01e']:02X} "
        f"$D01F=${vic['d01f']:02X}")
    out += [f"note: {note}" for note in report.notes]
    out += [f"printed: {line}".rstrip() for line in report.printed]  # through the ROM stubs (STROUT, LINPRT)
    if report.verdict is not None:
        out.append(f"verdict: {report.verdict.summary()}")
    return out + watch_lines(report)


def console_lines(report: ConsoleRun) -> list[str]:
    ppu = ppu_registers(report.ppu)
    out = _frames_run_lines(
        report, f"{report.instructions} instructions) from the reset vector ${report.entry:04X}",
        f"PPU: frame {ppu['frame']} line {ppu['line']} dot {ppu['dot']}, $2000=${ppu['ctrl']:02X} "
        f"$2001=${ppu['mask']:02X} $2002=${ppu['status']:02X}")
    if report.verdict is not None:
        out.append(f"verdict: {report.verdict.summary()}")
        if report.verdict.protocol == "$6000":
            out += [f"  {line}".rstrip() for line in report.verdict.text.splitlines()]
    return out + watch_lines(report)


def as_json(report: RunReport | ConsoleRun | C64Run) -> dict:
    """The object `retro run --json` prints (its keys are a contract: no trace in it)."""
    if isinstance(report, ConsoleRun):
        return console_json(report)
    if isinstance(report, C64Run):
        return c64_json(report)
    r = report.result
    return {"cycles": r.cycles, "instructions": r.instructions, "a": r.a, "x": r.x, "y": r.y, "s": r.s, "p": r.p,
            "peek": report.peeks, **({"raster": report.raster.as_dict()} if report.raster else {}),
            **({"notes": list(report.program.notes)} if report.program.notes else {}), **_watch_json(report),
            **({"vblank": report.vblank} if report.vblank else {})}


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


def lines(report: RunReport | ConsoleRun | C64Run) -> list[str]:
    if isinstance(report, ConsoleRun):
        return console_lines(report)
    if isinstance(report, C64Run):
        return c64_lines(report)
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
    v = report.vblank
    if v is not None:
        out.append(f"vblank: the call ran from scanline {v['start_line']} dot {v['start_dot']} to scanline "
                   f"{v['end_line']} dot {v['end_dot']}: {v['cycles']} cycles ({v['oam_dma_cycles']} of them OAM DMA), "
                   f"{v['vblank_cycles_left']} cycles of vblank left before rendering starts (pre-render line)")
    out += [f"{target}: " + " ".join(f"${v:02X}" for v in values) for target, values in report.peeks.items()]
    out += [f"note: {note}" for note in report.program.notes]  # e.g. a symbol file's skipped lines
    return out + watch_lines(report)


# The command line: this command's options and how it runs from them.

HELP = "call a 6502 routine in the emulator and report registers, cycles and memory"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("program", metavar="FILE.s|FILE.prg|FILE.bin|FILE.nes",
                   help="an Ophis source, a C64 .prg, a raw binary (with --load) or an iNES image (NROM)")
    p.add_argument("--entry", metavar="LABEL|ADDR", help="where the routine starts (called as by JSR); without it "
                   "the program runs as the machine would (--frames, --until, --until-value): an iNES image from its "
                   "reset vector, a C64 program from its BASIC SYS line; with those options, a C64 program from here")
    options.program_run(p)
    p.add_argument("--result", metavar="ADDR", help="a test program's result byte: an iNES image's (blargg's 2005 "
                   "ROMs: $F8, 1 = passed; the $6000 protocol is read without it), a C64 program's (VICE's test "
                   "programs: $D7FF, the run stops at its first write, $00 = passed, $FF = failed); exit 1 on a "
                   "failed verdict")
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
    options.scene_entry(p, "the call")
    output = p.add_mutually_exclusive_group()  # the JSON object's keys are fixed: no room for a trace
    output.add_argument("--trace", action="store_true", help="print every instruction executed (a program run: with "
                        "registers, flags, memory read and written and the beam position; needs a bound below)")
    p.add_argument("--trace-json", action="store_true", help="the trace as JSON lines, one per step (registers, "
                   "flags, memory read and written, the beam)")
    p.add_argument("--trace-limit", metavar="N", help="trace at most N steps")
    p.add_argument("--trace-cycles", metavar="FROM-TO", help="trace only these cycles of the run")
    p.add_argument("--trace-pc", metavar="LOW-HIGH", help="trace only instructions at these addresses (labels or numbers)")
    p.add_argument("--watch", dest="watches", action="append", default=[], metavar="KIND:ADDR[-ADDR][=V]",
                   help="report every read (r), write (w), read or write (rw) or execution (x) of an "
                        "address or range (a label or number), only of value V if given; repeatable")
    output.add_argument("--json", action="store_true", help="print one JSON object")


def _program_run_html(report) -> str:
    """A program run in a notebook: its trace listing (when traced) and its report."""
    traced = report.tracer is not None and report.tracer.bounds is not None
    return options.pre_html((program_trace_lines(report, False) if traced else []) + lines(report))


# The program runs' own modules (retro.analysis) know no text: the notebook display is this module's.
C64Run._repr_html_ = ConsoleRun._repr_html_ = _program_run_html


def main(args: argparse.Namespace) -> int:
    console = {"frames": args.frames, "until": args.until, "until_value": args.until_value, "result": args.result}
    if args.entry is None or wants_program_run(args.program, console):
        return _program_run_main(args, console)
    refuse_console_options(console)
    return _call_main(args)


def _program_run_main(args: argparse.Namespace, console: dict) -> int:
    """`retro run` of a whole program (a cartridge from reset, a C64 program from SYS or --entry):
    exit 1 on a test ROM's failed verdict."""
    entry_options = [name for name, given in (("--at-line", args.at_line), ("--at-cycle", args.at_cycle),
                                              ("--at-dot", args.at_dot), ("--in-nmi", args.in_nmi or None))
                     if given is not None]
    if entry_options:
        raise InputError(f"{', '.join(entry_options)}: where a call (--entry) starts on the scene's frame, "
                         f"not for a program run")
    report = run_console_or_refuse(args.program, labels=args.labels, peeks=args.peeks, load=args.load,
                                   scene=args.scene, trace=args.trace, cpu=args.cpu, entry=args.entry,
                                   trace_json=args.trace_json, trace_limit=args.trace_limit,
                                   trace_cycles=args.trace_cycles, trace_pc=args.trace_pc, watches=args.watches,
                                   **{k: v for k, v in console.items() if v is not None})
    if args.trace or args.trace_json:
        for line in program_trace_lines(report, args.trace_json):
            print(line)
    options.show(lines, as_json if args.json else None, report)
    return 1 if getattr(report, "verdict", None) is not None and report.verdict.passed is False else 0


def _call_main(args: argparse.Namespace) -> int:
    """`retro run --entry`: one call of a routine, through its RTS."""
    if args.trace and args.trace_json:
        raise InputError("--trace, --trace-json: one of them (a call's --trace lists every instruction)")
    # a call is bounded by its budget: --trace-json needs no bound of its own (the trace's own limit holds)
    wrap = trace_wrapper(args.program, trace=False, trace_json=args.trace_json,
                         trace_limit=args.trace_limit or (str(MAX_TRACE) if args.trace_json else None),
                         trace_cycles=args.trace_cycles, trace_pc=args.trace_pc, watches=args.watches,
                         labels=args.labels, load=args.load)
    flags = {flag: getattr(args, flag) for flag in SETTABLE_FLAGS if getattr(args, flag) is not None}
    report = run(args.program, args.entry, labels=args.labels, load=args.load, a=args.a, x=args.x, y=args.y,
                 flags=flags, sets=args.sets, peeks=args.peeks, budget=args.budget, scene=args.scene,
                 trace=args.trace, cpu=args.cpu, wrap=wrap, in_nmi=args.in_nmi, at_line=args.at_line,
                 at_cycle=args.at_cycle, at_dot=args.at_dot)
    if wrap is not None:
        report.tracer = wrap.made[0]
        if args.trace_json:
            for line in program_trace_lines(report, True):
                print(line)
    options.show(lines, as_json if args.json else None, report)
    return 0
