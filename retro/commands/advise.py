"""`retro advise`: the cheapest collision method (in 6502 cycles) good enough for a VIC-II or NES
scene's sprites, per test or, with `objects`, per frame."""

from __future__ import annotations

from pathlib import Path

from retro.analysis.check import check_engine
from retro.analysis.study.advisor import Advice, advice_lines
from retro.analysis.study.advisor import advise as advise_scene
from retro.analysis.study.broad_phase import MAX_OBJECTS
from retro.analysis.study.methods import with_user_methods
from retro.commands.chart import DEFAULT_JOBS, MAX_JOBS
from retro.errors import InputError
from retro.fileio import file_option
from retro.numbers import parse_int
from retro.progress import Progress, quiet
from retro.workers import configured, session
import argparse
from retro.commands import options
from retro.progress import progress_printer

DEFAULT_ACCURACY = 0.99


def accuracy_target(value: float | str) -> float:
    """--accuracy: a share in (0, 1] or a percentage ("99%")."""
    text = str(value).strip()
    try:
        target = float(text.rstrip("%")) / (100 if text.endswith("%") else 1)
    except ValueError:
        raise InputError(f"--accuracy: not a number: {text!r} (use 0.99 or 99%)") from None
    if not 0 < target <= 1:  # also refuses nan
        raise InputError(f"--accuracy: {text!r} is outside (0, 1] (use 0.99 or 99%)")
    return target


def advise(scene: str | Path, *, accuracy: float | str = DEFAULT_ACCURACY, methods: list[str] = (),
           software: bool = False, objects: int | str | None = None, jobs: int | str = DEFAULT_JOBS,
           engine: str = "auto", progress: Progress = quiet, scheduler: str | None = None) -> Advice:
    """Every method (built-in and the user's method files `methods`; without the hardware latch when
    `software`) measured on the scene's sprites; the cheapest one that decides at least `accuracy` of
    the cases correctly, per test or, for `objects` objects, per frame."""
    target = accuracy_target(accuracy)
    for method in methods:
        file_option(method, "--method")
    workers = configured(parse_int(jobs, field="--jobs", lo=1, hi=MAX_JOBS), scheduler)
    count = None if objects is None else parse_int(objects, field="--objects", lo=1, hi=MAX_OBJECTS)
    check_engine(engine)
    with session():  # its steps share one cluster
        return advise_scene(str(scene), target, workers=workers, progress=progress, methods=with_user_methods(methods),
                            software=software, objects=count, engine=engine)


def lines(advice: Advice) -> list[str]:
    return advice_lines(advice)


# The command line: this command's options and how it runs from them.

HELP = "the cheapest collision method (6502 cycles) that meets an accuracy target on a VIC-II or NES scene's sprites"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", metavar="SCENE.toml", help="a VIC-II scene (its enabled sprites) or an NES scene (its OAM "
                                                       "entries on screen): the objects to test")
    p.add_argument("--accuracy", default=str(DEFAULT_ACCURACY), metavar="A",
                   help=f"required share of cases decided correctly, 0-1 or a percentage (default: {DEFAULT_ACCURACY})")
    options.methods(p)
    options.engine(p)
    p.add_argument("--software", action="store_true",
                   help="software methods only: leave out the hardware latch (more objects than sprites, or when the "
                        "game must know which pair hit)")
    p.add_argument("--objects", metavar="N",
                   help="choose by 6502 cycles per frame for N objects (1-64, the scene's sprites in turn): "
                        "preparation, the cheaper broad phase (every pair or a sort along X) and the tests")
    options.jobs(p, DEFAULT_JOBS)
    options.scheduler(p)
    options.quiet(p)


def main(args: argparse.Namespace) -> int:
    result = advise(args.scene, accuracy=args.accuracy, methods=args.methods, software=args.software,
                    objects=args.objects, jobs=args.jobs, engine=args.engine, progress=progress_printer(args.quiet),
                    scheduler=args.scheduler)
    options.show(lines, None, result)
    return 0
