"""`retro profile`: where the cycles go, per subroutine (retro.analysis.profile; docs/profile.md).

What runs, as `retro run` would run it:
- a program: a C64 program from its BASIC SYS line (or `--entry` with --frames/--until/--until-value),
  an iNES image from its reset vector, for N frames or until a condition;
- a handler or routine: `--entry` alone calls it as by JSR (through its RTS), with `--scene`;
- a routine spec's cases (a built-in name or SPEC.toml): its first `--cases` planned cases on
  Machine, with `--scene`/`--at-line` as in `retro check`.
Text, `--json`, and `--png` (one frame of the beam: which subroutine ran on which line and cycle).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from retro.analysis.profile import Profile, Profiler, finished, line_ranges, ppu_beam, vic_beam
from retro.commands import options
from retro.commands import run as run_command
from retro.cpu.machine import CALL_STACK_TOP, DEFAULT_BUDGET, MAX_BUDGET
from retro.errors import InputError
from retro.fileio import all_or_nothing, file_option
from retro.machines.c64 import KERNAL_IRQ_ENTRY, vic_of
from retro.machines.nes import ppu_of
from retro.numbers import parse_int

DEFAULT_CASES = 2_000
MAX_CASES = 1_000_000
SPEC_SUFFIX = ".toml"


@dataclass
class ProfileReport:
    profile: Profile
    run: object  # the C64Run / ConsoleRun / CallResult behind it (None for a spec's cases)
    png: Path | None = None

    # in a notebook (Jupyter): the table and, with a beam, the picture
    def _repr_html_(self) -> str:
        return options.pre_html(lines(self))

    def _repr_png_(self) -> bytes | None:
        if self.profile.beam is None:
            return None
        from retro.render.profile_image import profile_image
        return options.png_of(profile_image(self.profile))


def _beam_of(machine):
    """The machine's beam as its chip's clock stands now (None without a chip)."""
    vic, ppu = vic_of(machine), ppu_of(machine)
    return vic_beam(vic) if vic is not None else ppu_beam(ppu) if ppu is not None else None


def _profiler_for(machine, inner=None) -> Profiler:
    vic, ppu = vic_of(machine), ppu_of(machine)
    return Profiler(machine.mpu, beam=_beam_of(machine), inner=inner, nes=ppu is not None,
                    stubs=frozenset({KERNAL_IRQ_ENTRY}) if vic is not None else frozenset())


def _machine_name(machine) -> str:
    return "c64" if vic_of(machine) is not None else "nes" if ppu_of(machine) is not None else "none"


def _ba_low(machine):
    vic = vic_of(machine)
    return None if vic is None else vic.bus.low


def _is_spec(target: str) -> bool:
    from retro.routines.registry import builtin_names
    return str(target).lower().endswith(SPEC_SUFFIX) or str(target) in builtin_names()


def _program_run(target, *, entry, frames, until, until_value, labels, load, scene) -> ProfileReport:
    made: list[Profiler] = []

    def wrap(machine, watch):
        profiler = _profiler_for(machine, watch)
        profiler.enter(machine.mpu.pc)
        made.append(profiler)
        return profiler

    given = {k: v for k, v in (("frames", frames), ("until", until), ("until_value", until_value)) if v is not None}
    if run_command.is_cartridge(target):
        if entry is not None or scene is not None or load is not None:
            raise InputError("--entry, --scene, --load: not for a cartridge run from reset (an iNES image is "
                             "profiled from its reset vector)")
        ran = run_command.run_console(target, labels=labels, wrap=wrap, **given)
    else:
        ran = run_command.run_c64_program(target, entry=entry, labels=labels, load=load, scene=scene, wrap=wrap,
                                          **given)
    machine = ran.machine
    profile = finished(made[0], machine=_machine_name(machine), source=f"program run ({ran.stopped})",
                       symbols=machine.symbols, notes=list(getattr(ran, "notes", ())), ba_low=_ba_low(machine))
    return ProfileReport(profile, ran)


def _call(target, *, entry, labels, load, start, budget) -> ProfileReport:
    """A handler or routine called as by JSR (retro run --entry's machine), profiled."""
    from retro.loaders import load_program

    program = load_program(target, symbols=file_option(labels, "--labels"), load=load)
    machine = options.call_machine(start, program.cpu)
    machine.load(program)
    address = machine.resolve(entry, "--entry")
    profiler = _profiler_for(machine)
    profiler.enter(address, sp=CALL_STACK_TOP)
    result = machine.call(address, budget=budget, observer=profiler)
    profile = finished(profiler, machine=_machine_name(machine), source="call", symbols=machine.symbols,
                       ba_low=_ba_low(machine))
    return ProfileReport(profile, result)


def _cases(target, *, start, cases, seed) -> ProfileReport:
    """The first `cases` planned cases of a routine spec, each called on Machine, profiled together."""
    from retro.routines import cases as case_sets
    from retro.routines.registry import get
    from retro.routines.runner import RoutineRunner

    routine = get(str(target))
    seed = routine.seed if seed is None else parse_int(seed, field="--seed", lo=0, hi=2**32 - 1)
    runner = RoutineRunner(routine, seed, start)
    machine = runner.machine
    profiler = _profiler_for(machine)
    done = 0
    for part in case_sets.plan(routine, exhaustive=False, seed=seed):
        for case in part.cases:
            if done >= cases:
                break
            writes, registers, p = runner.inputs_for_call(case)
            if runner.start is not None:
                runner.restart_beam()
                profiler.beam = _beam_of(machine)  # each call's own start on the frame
            profiler.enter(runner.entry, sp=CALL_STACK_TOP)
            machine.call(runner.entry, **registers, p=p, memory={address: [v] for address, v in writes},
                         budget=runner.limit, observer=profiler)
            done += 1
    profile = finished(profiler, machine=_machine_name(machine), source=f"{done} cases of {routine.name}",
                       symbols=machine.symbols, ba_low=_ba_low(machine))
    return ProfileReport(profile, None)


@all_or_nothing
def profile(target: str | Path, *, entry: str | None = None, frames: int | str | None = None,
            until: str | None = None, until_value: str | None = None, labels: str | Path | None = None,
            load: str | None = None, scene: str | Path | None = None, at_line: int | str | None = None,
            at_cycle: int | str | None = None, cases: int | str = DEFAULT_CASES, seed: int | str | None = None,
            budget: int | str = DEFAULT_BUDGET, png: str | Path | None = None, frame: int | str | None = None,
            at_dot: int | str | None = None, in_nmi: bool = False) -> ProfileReport:
    """Profile `target` (module docstring); `png` writes the picture of frame `frame` (default: the
    last frame the run covered whole)."""
    file_option(png, "--png")
    cases = parse_int(cases, field="--cases", lo=1, hi=MAX_CASES)
    budget = parse_int(budget, field="--budget", lo=1, hi=MAX_BUDGET)
    shown_frame = None if frame is None else parse_int(frame, field="--frame", lo=0, hi=MAX_BUDGET)
    if _is_spec(str(target)):
        if any(v is not None for v in (entry, frames, until, until_value, labels, load)):
            raise InputError("--entry, --frames, --until, --until-value, --labels, --load: not for a routine spec "
                             "(its cases are called as the spec says)")
        report = _cases(target, start=options.call_start(scene, at_line, at_cycle, at_dot, in_nmi), cases=cases,
                        seed=seed)
    elif entry is not None and frames is None and until is None and until_value is None:
        report = _call(target, entry=entry, labels=labels, load=load, budget=budget,
                       start=options.call_start(scene, at_line, at_cycle, at_dot, in_nmi))
    else:
        given = [name for name, value in (("--at-line", at_line), ("--at-cycle", at_cycle), ("--at-dot", at_dot),
                                          ("--in-nmi", in_nmi or None)) if value is not None]
        if given:
            raise InputError(f"{', '.join(given)}: where a spec's cases or a call (--entry) start, not for a program run")
        report = _program_run(target, entry=entry, frames=frames, until=until, until_value=until_value,
                              labels=labels, load=load, scene=scene)
    if png is not None:
        if report.profile.beam is None:
            raise InputError("--png: the picture shows the beam; this run has no VIC-II or PPU (give --scene)")
        from retro.render.images import save_png
        from retro.render.profile_image import profile_image

        report.png = save_png(profile_image(report.profile, shown_frame), png)
    return report


def routine_record(profile: Profile, stats) -> dict:
    lines = "all" if stats.all_lines else [list(r) for r in line_ranges(stats.lines)]
    return {"address": stats.address, "name": profile.name(stats.address), "kind": stats.kind, "calls": stats.calls,
            "open": stats.open, "inclusive": stats.inclusive, "exclusive": stats.exclusive,
            "min": stats.least, "mean": round(stats.mean, 2), "max": stats.most, "stolen": stats.stolen,
            "stolen_exclusive": stats.stolen_exclusive, "lines": lines}


def as_json(report: ProfileReport) -> dict:
    p = report.profile
    return {"machine": p.machine, "source": p.source, "cycles": p.cycles, "stolen": p.stolen,
            "line_unit": p.beam.unit if p.beam else None,
            "routines": [routine_record(p, s) for s in sorted(p.routines, key=lambda s: -s.inclusive)],
            "png": str(report.png) if report.png else None, "notes": p.notes}


def _lines_text(stats) -> str:
    if stats.all_lines:
        return "all"
    return ", ".join(f"{a}-{b}" if a != b else f"{a}" for a, b in line_ranges(stats.lines)) or "-"


def lines(report: ProfileReport) -> list[str]:
    p = report.profile
    stolen_by = {"c64": "the VIC-II", "nes": "OAM DMA"}.get(p.machine, "nothing")
    out = [f"profile of a {p.source}: {p.cycles} cycles, {p.stolen} stolen by {stolen_by} ({p.machine})",
           f"{'subroutine':<24} {'calls':>7} {'inclusive':>10} {'exclusive':>10} {'min':>7} {'mean':>9} {'max':>7} "
           f"{'stolen':>7} {'excl':>6}  {(p.beam.unit + 's') if p.beam else ''}"]
    for s in sorted(p.routines, key=lambda s: -s.inclusive):
        name = p.label(s) + (f" ${s.address:04X}" if p.name(s.address) != f"${s.address:04X}" else "")
        calls = f"{s.calls}" + ("*" if s.open else "")
        out.append(f"{name:<24} {calls:>7} {s.inclusive:>10} {s.exclusive:>10} {s.least or 0:>7} {s.mean:>9.2f} "
                   f"{s.most:>7} {s.stolen:>7} {s.stolen_exclusive:>6}  {_lines_text(s) if p.beam else ''}".rstrip())
    if any(s.open for s in p.routines):
        out.append("* still running when the run ended (closed there)")
    out += [f"note: {n}" for n in p.notes]
    if report.png:
        out.append(f"wrote {report.png}")
    return out


HELP = "where the cycles go: a profile per subroutine of a program run, a handler call or a spec's cases"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("target", metavar="FILE|SPEC", help="a C64 program (.prg, source), an iNES image, or a routine "
                   "spec (built-in name or SPEC.toml)")
    p.add_argument("--entry", metavar="LABEL|ADDR", help="call this routine or handler (as by JSR); with --frames, "
                   "--until or --until-value: run a C64 program from here")
    options.program_run(p)
    p.add_argument("--scene", metavar="SCENE.toml", help="a VIC-II scene (a C64 program run, a call, a spec's cases) "
                   "or a NES scene (a call, a spec's cases)")
    options.scene_entry(p, "a call (a spec: every call)")
    p.add_argument("--cases", default=str(DEFAULT_CASES), metavar="N",
                   help=f"spec: how many of its planned cases to run (default {DEFAULT_CASES:,})")
    p.add_argument("--seed", metavar="S", help="spec: the seed of its random cases")
    p.add_argument("--budget", default=str(DEFAULT_BUDGET), metavar="CYCLES", help="a call's cycle budget")
    p.add_argument("--png", metavar="OUT.png", help="write one frame of the beam: which subroutine ran where")
    p.add_argument("--frame", metavar="K", help="the frame the picture shows (default: the last one run whole)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def main(args: argparse.Namespace) -> int:
    report = profile(args.target, entry=args.entry, frames=args.frames, until=args.until,
                     until_value=args.until_value, labels=args.labels, load=args.load, scene=args.scene,
                     at_line=args.at_line, at_cycle=args.at_cycle, at_dot=args.at_dot, in_nmi=args.in_nmi,
                     cases=args.cases, seed=args.seed,
                     budget=args.budget, png=args.png, frame=args.frame)
    options.show(lines, as_json if args.json else None, report)
    return 0
