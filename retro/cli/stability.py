"""`retro stability [--out DIR] [--reduced]`: where each collision method breaks."""

from __future__ import annotations

import argparse
from pathlib import Path

from retro.analysis.study.evaluate import quiet, stderr_progress
from retro.analysis.study.methods import with_user_methods
from retro.analysis.study.stability.run import run_stability
from retro.cli.chart import add_engine_option, add_method_option, apply_engine

DEFAULT_OUT = "retro-out/stability"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("stability", help="tunnelling, coordinate wrap, arithmetic range, edge conventions, latch "
                                         "pitfalls: charts, CSVs and a Markdown report")
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help=f"output folder (default: {DEFAULT_OUT})")
    p.add_argument("--reduced", action="store_true", help="fewer speeds and bounded searches: seconds")
    add_method_option(p)
    add_engine_option(p)
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=cmd_stability)


def cmd_stability(args: argparse.Namespace) -> int:
    apply_engine(args)
    methods = with_user_methods(args.method)
    output = run_stability(Path(args.out), reduced=args.reduced, progress=quiet if args.quiet else stderr_progress,
                           methods=methods)
    for line in output.lines:
        print(line)
    print(f"wrote {', '.join(p.name for p in output.files)} to {args.out} in {output.seconds:.1f} s")
    return 0
