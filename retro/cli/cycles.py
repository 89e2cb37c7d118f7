"""`retro cycles [ROUTINE|SPEC.toml ...] [--json]`: bytes and cycles of routines, built-in or the user's."""

from __future__ import annotations

import argparse
import json

from retro.analysis.check import run_checks
from retro.analysis.cost import COST_FIELDS, cost_row, format_cost_table
from retro.cli.check import add_case_options, case_options


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("cycles", help="bytes of code and tables, measured and static cycles, raster lines of "
                                      "routines (built-in or your own spec)")
    add_case_options(p)
    p.description = f"--json prints a list of objects with the fields {', '.join(COST_FIELDS)}"
    p.set_defaults(func=cmd_cycles)


def cmd_cycles(args: argparse.Namespace) -> int:
    checks = run_checks(args.routines, **case_options(args))
    if args.json:
        print(json.dumps([cost_row(c) for c in checks], indent=1))
    else:
        for line in format_cost_table(checks):
            print(line)
    return 1 if any(c.mismatches for c in checks) else 0
