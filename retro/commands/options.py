"""What the command modules share at the command line: the options several commands have, defined
once so each means the same everywhere (--jobs, --engine, --method, --quiet, --out, --scale), and how a
command's result is printed (its module's `lines` or `as_json`)."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Iterable

from retro.analysis.check import ENGINES
from retro.workers import MAX_WORKERS


def show(lines: Callable[..., Iterable[str]], to_json: Callable | None, result, indent: int | None = None) -> None:
    """A command's result as its module shows it: `to_json(result)` printed as JSON when given (--json),
    else `lines(result)`."""
    if to_json is not None:
        print(json.dumps(to_json(result), indent=indent))
    else:
        for line in lines(result):
            print(line)


def out(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument("--out", default=default, metavar="DIR", help=f"output folder (default: {default})")


def jobs(p: argparse.ArgumentParser, default: int | None) -> None:
    """--jobs; default None leaves the count to the command (the checker: up to 2)."""
    p.add_argument("--jobs", default=default, metavar="N",
                   help=f"worker processes (default: {'up to 2' if default is None else default}; at most {MAX_WORKERS})")


def quiet(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")


def methods(p: argparse.ArgumentParser) -> None:
    p.add_argument("--method", dest="methods", action="append", default=[], metavar="FILE.toml",
                   help="a method of your own: a routine spec plus a hitbox rule (docs/methods.md); repeatable")


def engine(p: argparse.ArgumentParser, detail: str = "") -> None:
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="which engine runs the 6502 calls: scalar (Machine), batch (the numpy batched core) or auto "
                        f"(batch for many calls; default){detail}")


def scale(p: argparse.ArgumentParser, what: str, top: int) -> None:
    p.add_argument("--scale", default="2", metavar="K", help=f"integer {what} scale 1-{top} (default 2)")
