"""`retro advise SCENE [--accuracy 0.99] [--software] [--objects N]`: the cheapest collision method good
enough for a scene's shapes (a VIC-II or an NES scene), per test or, with --objects, per frame."""

from __future__ import annotations

import argparse

from retro.analysis.study.advisor import advice_lines, advise
from retro.analysis.study.broad_phase import MAX_OBJECTS
from retro.analysis.study.evaluate import quiet, stderr_progress
from retro.analysis.study.methods import with_user_methods
from retro.cli.chart import add_engine_option, add_method_option, apply_engine
from retro.errors import InputError
from retro.numbers import parse_int

DEFAULT_ACCURACY = 0.99


def _accuracy(text: str) -> float:
    try:
        value = float(text.rstrip("%")) / (100 if text.endswith("%") else 1)
    except ValueError:
        raise InputError(f"--accuracy: not a number: {text!r} (use 0.99 or 99%)") from None
    if not 0 < value <= 1:
        raise InputError(f"--accuracy: {text!r} is outside (0, 1] (use 0.99 or 99%)")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("advise", help="the cheapest collision method (6502 cycles) that meets an accuracy target "
                                      "on a VIC-II or NES scene's sprites")
    p.add_argument("scene", metavar="SCENE.toml", help="a VIC-II scene (its enabled sprites) or an NES scene (its OAM "
                                                       "entries on screen): the objects to test")
    p.add_argument("--accuracy", default=str(DEFAULT_ACCURACY), metavar="A",
                   help=f"required share of cases decided correctly, 0-1 or a percentage (default: {DEFAULT_ACCURACY})")
    add_method_option(p)
    add_engine_option(p)
    p.add_argument("--software", action="store_true",
                   help="software methods only: leave out the hardware latch (more objects than sprites, or when the "
                        "game must know which pair hit)")
    p.add_argument("--objects", metavar="N",
                   help="choose by 6502 cycles per frame for N objects (1-64, the scene's sprites in turn): "
                        "preparation, the cheaper broad phase (every pair or a sort along X) and the tests")
    p.add_argument("--jobs", default="2", metavar="N", help="worker processes (default: 2)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=cmd_advise)


def cmd_advise(args: argparse.Namespace) -> int:
    apply_engine(args)
    target = _accuracy(args.accuracy)
    workers = parse_int(args.jobs, field="--jobs", lo=1, hi=64)
    objects = None if args.objects is None else parse_int(args.objects, field="--objects", lo=1, hi=MAX_OBJECTS)
    advice = advise(args.scene, target, workers=workers, progress=quiet if args.quiet else stderr_progress,
                    methods=with_user_methods(args.method), software=args.software, objects=objects)
    for line in advice_lines(advice):
        print(line)
    return 0
