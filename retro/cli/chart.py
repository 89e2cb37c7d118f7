"""`retro chart [--out DIR] [--reduced] [--method FILE.toml ...] [--sprites FILE ...] [--samples N] [--per-frame]`:
speed against accuracy of every collision method, and with --per-frame its cost per frame."""

from __future__ import annotations

import argparse
from pathlib import Path

from retro.analysis.check import ENGINES
from retro.analysis.study.chart_run import AUTO, REDUCED_COST_SAMPLES, run_chart, summary_lines
from retro.analysis.study.evaluate import quiet, stderr_progress
from retro.analysis.study.methods import with_user_methods
from retro.numbers import parse_int

DEFAULT_OUT = "retro-out/chart"
MAX_SAMPLES = 1_000_000


def add_method_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--method", action="append", default=[], metavar="FILE.toml",
                   help="a method of your own: a routine spec plus a hitbox rule (docs/methods.md); repeatable")


def add_engine_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="which engine runs the 6502 calls: scalar (Machine), batch (the numpy batched core) or auto "
                        "(batch for many calls; default)")


def apply_engine(args: argparse.Namespace) -> None:
    """Make --engine the default of every routine run of this command (workers inherit it)."""
    from retro.analysis import check
    from retro.analysis.study.methods import base

    base.ENGINE = check.DEFAULT_ENGINE = args.engine


def samples_option(text: str) -> int | None | str:
    if text == "auto":
        return AUTO
    if text == "all":
        return None
    return parse_int(text, field="--samples", lo=1, hi=MAX_SAMPLES)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("chart", help="chart 6502 cycles against accuracy for every collision method (PNG, CSV, Markdown)")
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help=f"output folder (default: {DEFAULT_OUT})")
    p.add_argument("--reduced", action="store_true", help="a small corpus (3 shapes) and fewer cycle samples: seconds")
    add_method_option(p)
    add_engine_option(p)
    p.add_argument("--sprites", action="append", default=[], metavar="FILE",
                   help="add a file's sprites to the corpus (raw .spr frames, SpritePad .spd, Spritemate .spm, a PNG "
                        "sprite or sheet, or a VIC-II scene's enabled sprites); repeatable")
    p.add_argument("--samples", default="auto", metavar="N",
                   help=f"cases per pair whose cycles are measured: a number, or `all` (default: all; "
                        f"{REDUCED_COST_SAMPLES} with --reduced)")
    p.add_argument("--per-frame", action="store_true",
                   help="also chart 6502 cycles per frame against the number of objects (1-64) for each method, "
                        "with its preparation and a broad phase (every pair, sort along X): per_frame.png/.csv/.md")
    p.add_argument("--jobs", default="2", metavar="N", help="worker processes (default: 2)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=cmd_chart)


def cmd_chart(args: argparse.Namespace) -> int:
    apply_engine(args)
    workers = parse_int(args.jobs, field="--jobs", lo=1, hi=64)
    samples = samples_option(args.samples)
    methods = with_user_methods(args.method)
    output = run_chart(Path(args.out), reduced=args.reduced, workers=workers,
                       progress=quiet if args.quiet else stderr_progress, cost_samples=samples, methods=methods,
                       sprite_files=tuple(args.sprites), per_frame=args.per_frame)
    for line in summary_lines(output):
        print(line)
    return 0
