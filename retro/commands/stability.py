"""`retro stability`: where each collision method breaks (tunnelling, coordinate wrap, arithmetic
range, edge conventions, latch pitfalls): charts, CSVs and a Markdown report."""

from __future__ import annotations

from pathlib import Path

from retro.analysis.check import check_engine
from retro.analysis.study.methods import with_user_methods
from retro.analysis.study.stability.run import StabilityOutput, run_stability
from retro.fileio import all_or_nothing
from retro.progress import Progress, quiet
import argparse
from retro.commands import options
from retro.progress import progress_printer

DEFAULT_OUT = "retro-out/stability"


@all_or_nothing
def stability(out: str | Path = DEFAULT_OUT, *, reduced: bool = False, methods: list[str] = (),
              engine: str = "auto", progress: Progress = quiet) -> StabilityOutput:
    """The stability study of the built-in methods and the user's method files `methods`;
    `reduced`: fewer speeds and bounded searches (seconds)."""
    check_engine(engine)
    return run_stability(Path(out), reduced=reduced, progress=progress, methods=with_user_methods(methods),
                         engine=engine)


def lines(output: StabilityOutput) -> list[str]:
    return output.lines + [f"wrote {', '.join(p.name for p in output.files)} to {output.files[0].parent} "
                           f"in {output.seconds:.1f} s"]


# The command line: this command's options and how it runs from them.

HELP = "tunnelling, coordinate wrap, arithmetic range, edge conventions, latch pitfalls: charts, CSVs and a Markdown report"


def add_options(p: argparse.ArgumentParser) -> None:
    options.out(p, DEFAULT_OUT)
    p.add_argument("--reduced", action="store_true", help="fewer speeds and bounded searches: seconds")
    options.methods(p)
    options.engine(p)
    options.quiet(p)


def main(args: argparse.Namespace) -> int:
    result = stability(args.out, reduced=args.reduced, methods=args.methods, engine=args.engine,
                       progress=progress_printer(args.quiet))
    options.show(lines, None, result)
    return 0
