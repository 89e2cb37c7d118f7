"""`retro chart`: 6502 cycles against accuracy of every collision method (PNG, CSV, Markdown), and
with `per_frame` each method's cost per frame for 1-64 objects."""

from __future__ import annotations

from pathlib import Path

from retro.analysis.check import check_engine
from retro.analysis.study.chart_run import AUTO, ChartOutput, run_chart, summary_lines
from retro.analysis.study.methods import with_user_methods
from retro.fileio import all_or_nothing
from retro.numbers import parse_int
from retro.progress import Progress, quiet
from retro.workers import MAX_WORKERS, configured, session
import argparse
from retro.analysis.study.chart_run import REDUCED_COST_SAMPLES
from retro.commands import options
from retro.progress import progress_printer

DEFAULT_OUT = "retro-out/chart"
DEFAULT_JOBS = 2
MAX_JOBS = MAX_WORKERS
MAX_SAMPLES = 1_000_000


def samples_count(samples: int | str | None) -> int | str | None:
    """--samples: a count, `all` (None: every case) or `auto` (every case; fewer with --reduced)."""
    if samples in ("auto", AUTO):
        return AUTO
    if samples in ("all", None):
        return None
    return parse_int(samples, field="--samples", lo=1, hi=MAX_SAMPLES)


@all_or_nothing
def chart(out: str | Path = DEFAULT_OUT, *, reduced: bool = False, methods: list[str] = (), sprites: list[str] = (),
          samples: int | str | None = "auto", per_frame: bool = False, jobs: int | str = DEFAULT_JOBS,
          engine: str = "auto", progress: Progress = quiet, shapes: tuple[str, ...] | None = None,
          scheduler: str | None = None) -> ChartOutput:
    """The speed/accuracy study of the built-in methods and the user's method files `methods` on the
    corpus (the named `shapes` of sprites/, all by default, then every sprite of the files `sprites`)."""
    workers = configured(parse_int(jobs, field="--jobs", lo=1, hi=MAX_JOBS), scheduler)
    cost_samples = samples_count(samples)
    check_engine(engine)
    with session():  # its steps share one cluster
        return run_chart(Path(out), reduced=reduced, workers=workers, progress=progress, shape_names=shapes,
                         cost_samples=cost_samples, methods=with_user_methods(methods), sprite_files=tuple(sprites),
                         per_frame=per_frame, engine=engine)


def lines(output: ChartOutput) -> list[str]:
    return summary_lines(output)


# The command line: this command's options and how it runs from them.

HELP = "chart 6502 cycles against accuracy for every collision method (PNG, CSV, Markdown)"


def add_options(p: argparse.ArgumentParser) -> None:
    options.out(p, DEFAULT_OUT)
    p.add_argument("--reduced", action="store_true", help="a small corpus (3 shapes) and fewer cycle samples: seconds")
    options.methods(p)
    options.engine(p)
    p.add_argument("--sprites", action="append", default=[], metavar="FILE",
                   help="add a file's sprites to the corpus (raw .spr frames, SpritePad .spd, Spritemate .spm, a PNG "
                        "sprite or sheet, or a VIC-II scene's enabled sprites); repeatable")
    p.add_argument("--samples", default="auto", metavar="N",
                   help=f"cases per pair whose cycles are measured: a number, or `all` (default: all; "
                        f"{REDUCED_COST_SAMPLES} with --reduced)")
    p.add_argument("--per-frame", action="store_true",
                   help="also chart 6502 cycles per frame against the number of objects (1-64) for each method, "
                        "with its preparation and a broad phase (every pair, sort along X): per_frame.png/.csv/.md")
    options.jobs(p, DEFAULT_JOBS)
    options.scheduler(p)
    options.quiet(p)


def main(args: argparse.Namespace) -> int:
    result = chart(args.out, reduced=args.reduced, methods=args.methods, sprites=args.sprites, samples=args.samples,
                   per_frame=args.per_frame, jobs=args.jobs, engine=args.engine, progress=progress_printer(args.quiet),
                   scheduler=args.scheduler)
    options.show(lines, None, result)
    return 0
