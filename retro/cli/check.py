"""`retro check [ROUTINE|SPEC.toml ...] [--exhaustive] [--json]`: routines against references, results and cycles."""

from __future__ import annotations

import argparse
import json
import sys

from retro.analysis.check import ENGINES, SceneStart, check_record, format_check, run_checks
from retro.errors import InputError
from retro.numbers import parse_int
from retro.routines.registry import builtin_names

MAX_RANDOM = 10 ** 9


def add_case_options(p: argparse.ArgumentParser) -> None:
    """Options `retro check` and `retro cycles` share."""
    p.add_argument("routines", nargs="*", metavar="ROUTINE|SPEC.toml",
                   help=f"built-in routine names ({' '.join(builtin_names())}; all when none is given) or routine "
                        "spec files (NAME.toml, docs/specs.md)")
    p.add_argument("--exhaustive", action="store_true",
                   help="the full run: every exhaustive set and sweep, and each spec's full random count (minutes)")
    p.add_argument("--seed", help="seed of the random cases and of random memory (default: the spec's, 0)")
    p.add_argument("--random", dest="random_count", metavar="N",
                   help="random cases per routine (default: the spec's count, at most 2,000 without --exhaustive)")
    p.add_argument("--jobs", metavar="N", help="worker processes (default: up to 2)")
    p.add_argument("--scene", metavar="SCENE.toml", help="run every call on a C64 with this VIC-II scene: the CPU "
                   "stalls on Bad Lines and sprite DMA, and the report gives raster lines from the start line")
    p.add_argument("--at-line", metavar="L", help="with --scene: the raster line each call starts at "
                   "(default: the scene's [cpu] start_line)")
    p.add_argument("--at-cycle", metavar="C", help="with --scene: the cycle in that line (default: the scene's)")
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="which engine runs the calls: scalar (Machine, the reference; the timing model checks every "
                        "call), batch (the numpy batched core, checked against Machine on the first 2,000 cases of each "
                        "part) or auto (batch from 20,000 cases; default)")
    p.add_argument("--json", action="store_true", help="print a JSON list, one object per routine")


def case_options(args: argparse.Namespace) -> dict:
    return {"exhaustive": args.exhaustive,
            "seed": None if args.seed is None else parse_int(args.seed, field="--seed", lo=0, hi=2 ** 63 - 1),
            "random_count": None if args.random_count is None else parse_int(args.random_count, field="--random",
                                                                             lo=0, hi=MAX_RANDOM),
            "jobs": None if args.jobs is None else parse_int(args.jobs, field="--jobs", lo=1, hi=64),
            "progress": progress, "start": scene_start(args), "engine": args.engine}


def scene_start(args: argparse.Namespace) -> SceneStart | None:
    if args.scene is None:
        if args.at_line is not None or args.at_cycle is not None:
            raise InputError("--at-line and --at-cycle go with --scene")
        return None
    return SceneStart(args.scene, None if args.at_line is None else parse_int(args.at_line, field="--at-line", lo=0, hi=1000),
                      None if args.at_cycle is None else parse_int(args.at_cycle, field="--at-cycle", lo=1, hi=100))


def progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("check", help="cross-check 6502 routines (built-in or your own spec) against their references "
                                     "(results and cycles); exit 1 on any mismatch or broken budget")
    add_case_options(p)
    p.set_defaults(func=cmd_check)


def cmd_check(args: argparse.Namespace) -> int:
    checks = run_checks(args.routines, **case_options(args))
    if args.json:
        print(json.dumps([check_record(c) for c in checks], indent=1))
    else:
        for check in checks:
            for line in format_check(check):
                print(line)
    return 1 if any(c.mismatches for c in checks) else 0
