"""`retro chart [--out DIR] [--reduced] [--jobs N]`: speed against accuracy of every method."""

from __future__ import annotations

import argparse
from pathlib import Path

from retro.analysis.study.chart_run import run_chart, summary_lines
from retro.analysis.study.evaluate import quiet, stderr_progress
from retro.numbers import parse_int

DEFAULT_OUT = "retro-out/chart"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("chart", help="chart 6502 cycles against accuracy for every collision method (PNG, CSV, Markdown)")
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help=f"output folder (default: {DEFAULT_OUT})")
    p.add_argument("--reduced", action="store_true", help="a small corpus (3 shapes) and fewer cycle samples: seconds")
    p.add_argument("--jobs", default="2", metavar="N", help="worker processes (default: 2)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=cmd_chart)


def cmd_chart(args: argparse.Namespace) -> int:
    workers = parse_int(args.jobs, field="--jobs", lo=1, hi=64)
    output = run_chart(Path(args.out), reduced=args.reduced, workers=workers,
                       progress=quiet if args.quiet else stderr_progress)
    for line in summary_lines(output):
        print(line)
    return 0
