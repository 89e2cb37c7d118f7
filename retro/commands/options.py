"""What the command modules share at the command line: the options several commands have, defined
once so each means the same everywhere (--jobs, --scheduler, --engine, --method, --quiet, --out, --scale), and how a
command's result is printed (its module's `lines` or `as_json`)."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Iterable

from retro.analysis.check import ENGINES
from retro.workers import MAX_WORKERS, SCHEDULER_ENV


def show(lines: Callable[..., Iterable[str]], to_json: Callable | None, result, indent: int | None = None) -> None:
    """A command's result as its module shows it: `to_json(result)` printed as JSON when given (--json),
    else `lines(result)`."""
    if to_json is not None:
        print(json.dumps(to_json(result), indent=indent))
    else:
        for line in lines(result):
            print(line)


def pre_html(lines: Iterable[str]) -> str:
    """A command's text as a notebook shows it (`_repr_html_`): the lines, escaped, in a <pre>."""
    import html
    return "<pre>" + html.escape("\n".join(lines)) + "</pre>"


def png_of(image) -> bytes:
    """A Pillow image as the PNG bytes a notebook shows (`_repr_png_`)."""
    from retro.render.images import png_bytes
    return png_bytes(image)


def out(p: argparse.ArgumentParser, default: str) -> None:
    p.add_argument("--out", default=default, metavar="DIR", help=f"output folder (default: {default})")


def jobs(p: argparse.ArgumentParser, default: int | None) -> None:
    """--jobs; default None leaves the count to the command (the checker: up to 2)."""
    p.add_argument("--jobs", default=default, metavar="N",
                   help=f"worker processes (default: {'up to 2' if default is None else default}; at most {MAX_WORKERS})")


def scheduler(p: argparse.ArgumentParser) -> None:
    """--scheduler, beside --jobs: the run's parallel work on an existing Dask cluster (docs/dask.md)."""
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help=f"run the parallel work on the Dask cluster whose scheduler is at ADDRESS (tcp://host:8786) "
                        f"instead of local worker processes (default: ${SCHEDULER_ENV} when set; docs/dask.md)")


def quiet(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")


def methods(p: argparse.ArgumentParser) -> None:
    p.add_argument("--method", dest="methods", action="append", default=[], metavar="FILE.toml",
                   help="a method of your own: a routine spec plus a hitbox rule (docs/methods.md); repeatable")


def engine(p: argparse.ArgumentParser, detail: str = "") -> None:
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="which engine runs the 6502 calls: scalar (Machine), batch (the numpy batched core), compiled "
                        "(native code through numba, docs/compiled.md; retro check only, the other commands run the "
                        f"batched core for it) or auto (batch for many calls, compiled for millions; default){detail}")


def scale(p: argparse.ArgumentParser, what: str, top: int) -> None:
    p.add_argument("--scale", default="2", metavar="K", help=f"integer {what} scale 1-{top} (default 2)")
