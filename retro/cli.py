"""The `retro` command line: parse, call one function of retro.commands, print its lines or its JSON.

Options mean the same in every command that has them (--jobs, --engine, --method, --quiet, --out,
--json, --scale). The command functions check their own arguments (numbers arrive as the text typed),
so nothing is validated twice. Every RetroError becomes one line on stderr and its exit code (2 for
bad input, 1 for a routine or check that fails); argparse usage errors exit 2.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable

from retro import __version__, interrupts
from retro.analysis.check import AGREEMENT_PER_PART, AUTO_BATCH_CASES, ENGINES
from retro.commands.cycles import COST_FIELDS
from retro.analysis.study.chart_run import REDUCED_COST_SAMPLES
from retro.chips.palettes import C64_DEFAULT_PALETTE
from retro.commands import advise, asm, chart, check, cycles, demo, nes, parry, run, stability, vic
from retro.cpu.machine import DEFAULT_BUDGET, MAX_BUDGET
from retro.errors import RetroError
from retro.geometry.parry import DEFAULT_FRAMES, MAX_FRAMES
from retro.workers import MAX_WORKERS
from retro.progress import progress_printer
from retro.routines.registry import builtin_names


def one_line(text: str) -> str:
    """User text (file names, TOML keys) echoed in a message can hold newlines or terminal escapes:
    show every control character as a Python escape so the error stays one plain line."""
    return "".join(repr(c)[1:-1] if ord(c) < 0x20 or ord(c) == 0x7F else c for c in text)


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("allow_abbrev", False)  # `--exhaustiv` must not pass for `--exhaustive`
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # one line, exit 2, no usage dump
        print(one_line(f"{self.prog}: {message}"), file=sys.stderr)
        raise SystemExit(2)


def _print(command, result, as_json: bool = False, indent: int | None = None) -> None:
    """A command's result as its module shows it: `as_json(result)` as JSON, or `lines(result)`."""
    if as_json:
        print(json.dumps(command.as_json(result), indent=indent))
    else:
        for line in command.lines(result):
            print(line)


# Options shared by several commands: one definition each, so each means the same everywhere.

def _out(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument("--out", default=default, metavar="DIR", help=f"output folder (default: {default})")


def _jobs(p: argparse.ArgumentParser, default: int | None) -> None:
    """--jobs; default None leaves the count to the command (the checker: up to 2)."""
    p.add_argument("--jobs", default=default, metavar="N",
                   help=f"worker processes (default: {'up to 2' if default is None else default}; at most {MAX_WORKERS})")


def _quiet(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")


def _methods(p: argparse.ArgumentParser) -> None:
    p.add_argument("--method", dest="methods", action="append", default=[], metavar="FILE.toml",
                   help="a method of your own: a routine spec plus a hitbox rule (docs/methods.md); repeatable")


def _engine(p: argparse.ArgumentParser, detail: str = "") -> None:
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="which engine runs the 6502 calls: scalar (Machine), batch (the numpy batched core) or auto "
                        f"(batch for many calls; default){detail}")


def _scale(p: argparse.ArgumentParser, what: str, top: int) -> None:
    p.add_argument("--scale", default="2", metavar="K", help=f"integer {what} scale 1-{top} (default 2)")


# One function per command: parse -> call -> print -> exit code.

def _cmd_demo(args: argparse.Namespace) -> int:
    demo.demo(args.out)
    return 0


def _cmd_asm(args: argparse.Namespace) -> int:
    _print(asm, asm.asm(args.source, output=args.output, labels=args.labels, listing=args.listing, cpu=args.cpu))
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    console = {"frames": args.frames, "until": args.until, "until_value": args.until_value, "result": args.result}
    if args.entry is None or run.wants_program_run(args.program, console):
        report = run.run_console_or_refuse(args.program, labels=args.labels, peeks=args.peeks, load=args.load,
                                           scene=args.scene, trace=args.trace, cpu=args.cpu, entry=args.entry,
                                           **{k: v for k, v in console.items() if v is not None})
        _print(run, report, args.json)
        return 1 if getattr(report, "verdict", None) is not None and report.verdict.passed is False else 0
    run.refuse_console_options(console)
    flags = {flag: getattr(args, flag) for flag in run.SETTABLE_FLAGS if getattr(args, flag) is not None}
    report = run.run(args.program, args.entry, labels=args.labels, load=args.load, a=args.a, x=args.x, y=args.y,
                     flags=flags, sets=args.sets, peeks=args.peeks, budget=args.budget, scene=args.scene,
                     trace=args.trace, cpu=args.cpu)
    _print(run, report, args.json)
    return 0


def _cmd_vic(args: argparse.Namespace) -> int:
    _print(vic, vic.vic(args.scene, frames=args.frames, png=args.png, scale=args.scale, palette=args.palette,
                        pixels=args.pixels), args.json)
    return 0


def _cmd_nes(args: argparse.Namespace) -> int:
    _print(nes, nes.nes(args.scene, png=args.png, scale=args.scale), args.json)
    return 0


def _checks(args: argparse.Namespace) -> list:
    return check.check(args.routines, exhaustive=args.exhaustive, seed=args.seed, random=args.random, jobs=args.jobs,
                       scene=args.scene, at_line=args.at_line, at_cycle=args.at_cycle, engine=args.engine,
                       progress=progress_printer(args.quiet))


def _cmd_check(args: argparse.Namespace) -> int:
    checks = _checks(args)
    _print(check, checks, args.json, indent=1)
    if args.junit:
        check.write_junit(checks, args.junit, scene=args.scene)
    return 1 if check.failed(checks) else 0


def _cmd_cycles(args: argparse.Namespace) -> int:
    checks = _checks(args)
    _print(cycles, checks, args.json, indent=1)
    return 1 if cycles.failed(checks) else 0


def _cmd_chart(args: argparse.Namespace) -> int:
    _print(chart, chart.chart(args.out, reduced=args.reduced, methods=args.methods, sprites=args.sprites,
                              samples=args.samples, per_frame=args.per_frame, jobs=args.jobs, engine=args.engine,
                              progress=progress_printer(args.quiet)))
    return 0


def _cmd_stability(args: argparse.Namespace) -> int:
    _print(stability, stability.stability(args.out, reduced=args.reduced, methods=args.methods, engine=args.engine,
                                          progress=progress_printer(args.quiet)))
    return 0


def _cmd_advise(args: argparse.Namespace) -> int:
    _print(advise, advise.advise(args.scene, accuracy=args.accuracy, methods=args.methods, software=args.software,
                                 objects=args.objects, jobs=args.jobs, engine=args.engine,
                                 progress=progress_printer(args.quiet)))
    return 0


def _cmd_parry(args: argparse.Namespace) -> int:
    _print(parry, parry.parry(args.script, out=args.out, frames=args.frames))
    return 0


def _add(sub: argparse._SubParsersAction, name: str, run_it: Callable[[argparse.Namespace], int],
         **kwargs) -> argparse.ArgumentParser:
    p = sub.add_parser(name, **kwargs)
    p.set_defaults(func=run_it)
    return p


def _routine_options(p: argparse.ArgumentParser) -> None:
    """What `retro check` and `retro cycles` share: the same run, two views."""
    p.add_argument("routines", nargs="*", metavar="ROUTINE|SPEC.toml",
                   help=f"built-in routine names ({' '.join(builtin_names())}; all when none is given) or routine "
                        "spec files (NAME.toml, docs/specs.md)")
    p.add_argument("--exhaustive", action="store_true",
                   help="the full run: every exhaustive set and sweep, and each spec's full random count (minutes)")
    p.add_argument("--seed", help="seed of the random cases and of random memory (default: the spec's, 0)")
    p.add_argument("--random", metavar="N",
                   help="random cases per routine (default: the spec's count, at most 2,000 without --exhaustive)")
    _jobs(p, None)
    p.add_argument("--scene", metavar="SCENE.toml", help="run every call on a C64 with this VIC-II scene: the CPU "
                   "stalls on Bad Lines and sprite DMA, and the report gives raster lines from the start line")
    p.add_argument("--at-line", metavar="L", help="with --scene: the raster line each call starts at "
                   "(default: the scene's [cpu] start_line)")
    p.add_argument("--at-cycle", metavar="C", help="with --scene: the cycle in that line (default: the scene's)")
    _engine(p, f"; scalar is the reference and the timing model checks every call, batch is checked against Machine "
               f"on the first {AGREEMENT_PER_PART:,} cases of each part, auto takes batch from {AUTO_BATCH_CASES:,} cases")
    p.add_argument("--json", action="store_true", help="print a JSON list, one object per routine")
    _quiet(p)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="retro", description="Collision detection on retro hardware (C64, NES).")
    parser.add_argument("--version", action="version", version=f"retro {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    p = _add(sub, "demo", _cmd_demo, help="run the built-in examples; writes its files into one folder")
    _out(p, "retro-out")

    p = _add(sub, "asm", _cmd_asm, help="assemble a 6502 source (Ophis syntax) into a PRG and a VICE label file")
    p.add_argument("source", metavar="FILE.s", help="a 6502 source in Ophis syntax")
    p.add_argument("-o", "--output", metavar="OUT.prg", help="PRG to write (default: FILE.prg)")
    p.add_argument("--labels", metavar="OUT.lbl", help="VICE label file to write")
    p.add_argument("--list", dest="listing", metavar="OUT.lst", help="listing to write")
    p.add_argument("--cpu", metavar="CPU", help="65c02: assemble the WDC 65C02's opcodes (default: the NMOS "
                                                "6502's, undocumented ones included)")

    p = _add(sub, "run", _cmd_run, help="call a 6502 routine in the emulator and report registers, cycles and memory")
    p.add_argument("program", metavar="FILE.s|FILE.prg|FILE.bin|FILE.nes",
                   help="an Ophis source, a C64 .prg, a raw binary (with --load) or an iNES image (NROM)")
    p.add_argument("--labels", metavar="F", help="symbol file of a .prg, .bin or .nes, in any supported format "
                                                   "(docs/symbols.md)")
    p.add_argument("--load", metavar="ADDR", help="load address of a raw binary")
    p.add_argument("--entry", metavar="LABEL|ADDR", help="where the routine starts (called as by JSR); without it "
                   "an iNES image runs on a console from its reset vector (--frames, --until, --until-value, --result)")
    p.add_argument("--frames", metavar="N", help=f"iNES image from reset: frames to run (default {run.DEFAULT_FRAMES}, "
                   f"at most {run.MAX_FRAMES:,}); the run also stops when the program halts (JMP * with the NMI off)")
    p.add_argument("--until", metavar="LABEL|ADDR", help="iNES image from reset: stop when the PC reaches this address")
    p.add_argument("--until-value", metavar="TARGET=V", help="iNES image from reset: stop when this byte holds V")
    p.add_argument("--result", metavar="ADDR", help="iNES image from reset: a test ROM's result byte (blargg's 2005 "
                   "ROMs: $F8, 1 = passed); the $6000 protocol is read without it; exit 1 on a failed verdict")
    for register in ("a", "x", "y"):
        p.add_argument(f"--{register}", default="0", metavar="V", help=f"{register.upper()} on entry (default 0)")
    for flag in run.SETTABLE_FLAGS:
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

    p = _add(sub, "vic", _cmd_vic, help="predict the VIC-II collision registers for a scene; draw the overlaps")
    p.add_argument("scene", metavar="SCENE.toml", help="a VIC-II scene file (docs/vic.md)")
    p.add_argument("--frames", default="1", metavar="N",
                   help=f"frames to run (default 1, at most {vic.MAX_FRAMES:,}): sprites with a velocity move each "
                        "frame, and each frame's latches are reported as a program reading them once a frame sees them")
    p.add_argument("--json", action="store_true", help="print one JSON object: d01e, d01f, d019, first, pairs, "
                                                       "background")
    p.add_argument("--pixels", action="store_true", help="list every overlap pixel (raster line, X) of each pair "
                                                         "and each sprite over graphics")
    p.add_argument("--png", metavar="OUT.png", help="write the frame with the overlaps marked")
    _scale(p, "image", vic.MAX_SCALE)
    p.add_argument("--palette", default=C64_DEFAULT_PALETTE,
                   help=f"{' or '.join(vic.C64_PALETTES)} (default: {C64_DEFAULT_PALETTE})")

    p = _add(sub, "nes", _cmd_nes, help="predict the NES sprite-zero hit ($2002 bit 6) of a scene: pixel, line, dot")
    p.add_argument("scene", metavar="SCENE.toml")
    p.add_argument("--json", action="store_true", help="print one JSON object: hit, line, dot, x, dots_after_vblank, "
                                                       "cpu_cycles_after_vblank")
    p.add_argument("--png", metavar="OUT.png", help="write a picture of the frame and sprite 0")
    _scale(p, "picture", nes.MAX_SCALE)

    p = _add(sub, "check", _cmd_check, help="cross-check 6502 routines (built-in or your own spec) against their "
                                            "references (results and cycles); exit 1 on any mismatch or broken budget")
    _routine_options(p)
    p.add_argument("--junit", metavar="FILE.xml", help="also write the results as JUnit XML for CI: one testcase per "
                                                       "routine, a failure carrying its report")

    p = _add(sub, "cycles", _cmd_cycles, help="bytes of code and tables, measured and static cycles, raster lines of "
                                              "routines (built-in or your own spec)",
             description=f"--json prints a list of objects with the fields {', '.join(COST_FIELDS)}")
    _routine_options(p)

    p = _add(sub, "chart", _cmd_chart, help="chart 6502 cycles against accuracy for every collision method "
                                            "(PNG, CSV, Markdown)")
    _out(p, chart.DEFAULT_OUT)
    p.add_argument("--reduced", action="store_true", help="a small corpus (3 shapes) and fewer cycle samples: seconds")
    _methods(p)
    _engine(p)
    p.add_argument("--sprites", action="append", default=[], metavar="FILE",
                   help="add a file's sprites to the corpus (raw .spr frames, SpritePad .spd, Spritemate .spm, a PNG "
                        "sprite or sheet, or a VIC-II scene's enabled sprites); repeatable")
    p.add_argument("--samples", default="auto", metavar="N",
                   help=f"cases per pair whose cycles are measured: a number, or `all` (default: all; "
                        f"{REDUCED_COST_SAMPLES} with --reduced)")
    p.add_argument("--per-frame", action="store_true",
                   help="also chart 6502 cycles per frame against the number of objects (1-64) for each method, "
                        "with its preparation and a broad phase (every pair, sort along X): per_frame.png/.csv/.md")
    _jobs(p, chart.DEFAULT_JOBS)
    _quiet(p)

    p = _add(sub, "stability", _cmd_stability, help="tunnelling, coordinate wrap, arithmetic range, edge conventions, "
                                                    "latch pitfalls: charts, CSVs and a Markdown report")
    _out(p, stability.DEFAULT_OUT)
    p.add_argument("--reduced", action="store_true", help="fewer speeds and bounded searches: seconds")
    _methods(p)
    _engine(p)
    _quiet(p)

    p = _add(sub, "advise", _cmd_advise, help="the cheapest collision method (6502 cycles) that meets an accuracy "
                                              "target on a VIC-II or NES scene's sprites")
    p.add_argument("scene", metavar="SCENE.toml", help="a VIC-II scene (its enabled sprites) or an NES scene (its OAM "
                                                       "entries on screen): the objects to test")
    p.add_argument("--accuracy", default=str(advise.DEFAULT_ACCURACY), metavar="A",
                   help=f"required share of cases decided correctly, 0-1 or a percentage "
                        f"(default: {advise.DEFAULT_ACCURACY})")
    _methods(p)
    _engine(p)
    p.add_argument("--software", action="store_true",
                   help="software methods only: leave out the hardware latch (more objects than sprites, or when the "
                        "game must know which pair hit)")
    p.add_argument("--objects", metavar="N",
                   help="choose by 6502 cycles per frame for N objects (1-64, the scene's sprites in turn): "
                        "preparation, the cheaper broad phase (every pair or a sort along X) and the tests")
    _jobs(p, chart.DEFAULT_JOBS)
    _quiet(p)

    p = _add(sub, "parry", _cmd_parry, help="run the Sekiro-style parry loop on a scripted input; writes a GIF and PNGs",
             description="Script: FRAME:ACTION tokens (ACTION = parry, left, right or stop), e.g. '40:parry 90:left "
                         "110:stop'; '@FILE' reads them from a file (one or more per line, '#' starts a comment).")
    p.add_argument("--script", metavar="SCRIPT", help="input script or @FILE (default: a built-in script)")
    _out(p, parry.DEFAULT_OUT)
    p.add_argument("--frames", default=str(DEFAULT_FRAMES), metavar="N",
                   help=f"frames to simulate (default: {DEFAULT_FRAMES}, at most {MAX_FRAMES:,})")
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except RetroError as exc:
        print(one_line(f"retro {args.command}: {exc}"), file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM/SIGHUP once retro.entry installed its handlers
        print(f"retro {args.command}: {interrupts.describe(exc)}", file=sys.stderr)
        return interrupts.exit_code(exc)
    except BrokenPipeError:
        return 1
