"""`retro cycles [ROUTINE ...] [--json]`: bytes and cycles of the collision routines."""

from __future__ import annotations

import argparse
import json
import sys

from retro.analysis.check import run_checks
from retro.analysis.cost import cost_row, format_cost_table
from retro.numbers import parse_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("cycles", help="bytes of code and tables, measured and static cycles of the collision routines")
    p.add_argument("routines", nargs="*", metavar="ROUTINE", help="aabb8 aabb_sprite circle mul8 tile tile_box pixel")
    p.add_argument("--exhaustive", action="store_true", help="measure over the full case set of `retro check --exhaustive`")
    p.add_argument("--seed", default="0", help="seed of the random cases")
    p.add_argument("--json", action="store_true", help="print a JSON list of objects with the fields routine, "
                   "code_bytes, table_bytes, min, mean, max, static_min, static_max, cases, mismatches")
    p.set_defaults(func=cmd_cycles)


def cmd_cycles(args: argparse.Namespace) -> int:
    checks = run_checks(args.routines, exhaustive=args.exhaustive, seed=parse_int(args.seed, field="--seed", lo=0),
                        progress=lambda message: print(message, file=sys.stderr, flush=True))
    if args.json:
        print(json.dumps([cost_row(c) for c in checks], indent=1))
    else:
        for line in format_cost_table(checks):
            print(line)
    return 1 if any(c.mismatches for c in checks) else 0
