"""`retro demo [--out DIR]`: every capability of the toolkit on built-in examples."""

from __future__ import annotations

import argparse
from pathlib import Path

from retro.demo import run_demo

DEFAULT_OUT = "retro-out"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="run the built-in examples; writes its files into one folder")
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help=f"output folder (default: {DEFAULT_OUT})")
    p.set_defaults(func=cmd_demo)


def cmd_demo(args: argparse.Namespace) -> int:
    run_demo(Path(args.out))
    return 0
