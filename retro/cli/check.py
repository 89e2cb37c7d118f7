"""`retro check [ROUTINE ...] [--exhaustive] [--json]`: routines against references, results and cycles."""

from __future__ import annotations

import argparse
import json
import sys

from retro.analysis.check import check_record, format_check, run_checks
from retro.numbers import parse_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("check", help="cross-check the 6502 collision routines against their references "
                                     "(results and cycles); exit 1 on any mismatch")
    p.add_argument("routines", nargs="*", metavar="ROUTINE", help="aabb8 aabb_sprite circle mul8 tile tile_box pixel")
    p.add_argument("--exhaustive", action="store_true",
                   help="the full run: exhaustive sweeps and 100,000 random cases per routine (minutes)")
    p.add_argument("--seed", default="0", help="seed of the random cases and of the screen/mask world")
    p.add_argument("--random", dest="random_count", metavar="N", help="random cases per routine")
    p.add_argument("--jobs", metavar="N", help="worker processes (default: up to 2)")
    p.add_argument("--json", action="store_true", help="print a JSON list, one object per routine")
    p.set_defaults(func=cmd_check)


def _progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def cmd_check(args: argparse.Namespace) -> int:
    checks = run_checks(args.routines, exhaustive=args.exhaustive, seed=parse_int(args.seed, field="--seed", lo=0),
                        random_count=None if args.random_count is None else parse_int(args.random_count, field="--random", lo=0),
                        jobs=None if args.jobs is None else parse_int(args.jobs, field="--jobs", lo=1, hi=64),
                        progress=_progress)
    if args.json:
        print(json.dumps([check_record(c) for c in checks], indent=1))
    else:
        for check in checks:
            for line in format_check(check):
                print(line)
    return 1 if any(c.mismatches for c in checks) else 0
