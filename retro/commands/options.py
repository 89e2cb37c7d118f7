"""What the command modules share at the command line: the options several commands have, defined
once so each means the same everywhere (--jobs, --scheduler, --engine, --method, --quiet, --out, --scale, the
program run's --labels, --load, --frames, --until, --until-value), and how a command's result is printed (its
module's `lines` or `as_json`)."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Iterable
from pathlib import Path

from retro.analysis.c64_run import DEFAULT_C64_FRAMES
from retro.analysis.check import ENGINES, SceneStart
from retro.analysis.console_run import DEFAULT_FRAMES, MAX_FRAMES
from retro.errors import InputError
from retro.fileio import file_option
from retro.numbers import parse_int
from retro.routines.chip_access import NesStart
from retro.routines.runner import RasterStart
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
                        f"batched core for it) or auto (batch for many calls, compiled when their work pays for its start; default){detail}")


def scale(p: argparse.ArgumentParser, what: str, top: int) -> None:
    p.add_argument("--scale", default="2", metavar="K", help=f"integer {what} scale 1-{top} (default 2)")


def program_run(p: argparse.ArgumentParser) -> None:
    """The program run `retro run` and `retro profile` share: the program as loaded (--labels, --load)
    and its run as the machine would run it, for N frames or until a condition (--frames, --until,
    --until-value); the command checks which of them its other options allow."""
    group = p.add_argument_group("program run", "the program file's symbols and load address; a run of the "
                                 "program for N frames or until a condition")
    group.add_argument("--labels", metavar="F", help="symbol file of a .prg, .bin or .nes, in any supported format "
                                                       "(docs/symbols.md): the names of entries, stops, peeks and "
                                                       "(retro profile) subroutines")
    group.add_argument("--load", metavar="ADDR", help="load address of a raw binary")
    group.add_argument("--frames", metavar="N", help=f"program run: frames to run (default {DEFAULT_FRAMES} on a NES, "
                       f"{DEFAULT_C64_FRAMES} on a C64, at most {MAX_FRAMES:,}); the run also stops when the program "
                       f"halts (JMP * with no interrupt to come)")
    group.add_argument("--until", metavar="LABEL|ADDR", help="program run: stop when the PC reaches this address")
    group.add_argument("--until-value", metavar="TARGET=V", help="program run: stop when this byte holds V")
def scene_entry(p: argparse.ArgumentParser, what: str = "each call") -> None:
    """Where `what` starts on a --scene's frame: --at-line with --at-cycle (a VIC-II scene) or --at-dot
    (a NES scene), or --in-nmi (a NES scene: as the NMI handler); checked against the scene's chip."""
    p.add_argument("--at-line", metavar="L", help=f"with --scene: the raster line (a NES scene: the scanline) {what} "
                   "starts at (default: a VIC-II scene's [cpu] start_line; a NES scene's line 0)")
    p.add_argument("--at-cycle", metavar="C", help="with a VIC-II --scene: the cycle in that line (default: the scene's)")
    p.add_argument("--at-dot", metavar="D", help="with a NES --scene: the dot in that scanline, 0-340 (default 0); "
                   f"{what} starts at the first CPU cycle beginning at or after it")
    p.add_argument("--in-nmi", action="store_true", help=f"with a NES --scene: {what} is the NMI handler, entered at "
                   "the start of vblank (scanline 241, the vblank flag set), and the report gives the vblank cycles "
                   "left before rendering starts (OAM DMA counted)")


MAX_AT = 1000  # above every chip's line, cycle and dot count: the scene's chip gives the exact range
NEEDS_NES = "needs a NES scene (--scene with chip = \"nes\")"


def _scene_options(scene: str | Path | None, at_line: int | str | None, at_cycle: int | str | None,
                   at_dot: int | str | None, in_nmi: bool) -> SceneStart | None:
    """--scene and the `scene_entry` options as plain data (None without a scene), each option's own
    range checked; the scene's chip is not read yet."""
    nes_only = [name for name, given in (("--at-dot", at_dot is not None), ("--in-nmi", in_nmi)) if given]
    if file_option(scene, "--scene") is None:
        if nes_only:
            raise InputError(f"{nes_only[0]}: {NEEDS_NES}")
        if at_line is not None or at_cycle is not None:
            raise InputError("--at-line and --at-cycle go with --scene")
        return None
    return SceneStart(str(scene), None if at_line is None else parse_int(at_line, field="--at-line", lo=0, hi=MAX_AT),
                      None if at_cycle is None else parse_int(at_cycle, field="--at-cycle", lo=1, hi=MAX_AT),
                      None if at_dot is None else parse_int(at_dot, field="--at-dot", lo=0, hi=MAX_AT), in_nmi)


def scene_start(scene: str | Path | None, at_line: int | str | None = None, at_cycle: int | str | None = None,
                at_dot: int | str | None = None, in_nmi: bool = False) -> SceneStart | None:
    """--scene and the `scene_entry` options as a SceneStart (None without a scene), the plain data a
    check sends to its workers, every option checked against the scene's chip before any work starts
    (one-line errors)."""
    start = _scene_options(scene, at_line, at_cycle, at_dot, in_nmi)
    if start is not None:
        start.raster_start()
    return start


def call_start(scene: str | Path | None, at_line: int | str | None = None, at_cycle: int | str | None = None,
               at_dot: int | str | None = None, in_nmi: bool = False) -> RasterStart | NesStart | None:
    """The same options for work done in this process (`retro run --entry`, `retro profile`): the scene
    read once, as the RasterStart/NesStart its machine is built from (None without a scene)."""
    start = _scene_options(scene, at_line, at_cycle, at_dot, in_nmi)
    return None if start is None else start.raster_start()


def call_machine(where: RasterStart | NesStart | None, cpu: str | None):
    """The machine one call runs on (`retro run --entry`, `retro profile --entry`): a bare CPU without
    a scene; with one (`call_start`), its chip where `where` puts the call: a VIC-II's beam at
    --at-line/--at-cycle (default: the scene's [cpu] start), a NES's PPU at --at-line/--at-dot or the
    NMI handler's start with the frame drawn so far."""
    from dataclasses import replace

    from retro.machines import build_machine
    from retro.machines.nes import enter_frame

    if where is None:
        return build_machine(None, cpu=cpu)
    if isinstance(where, NesStart):
        machine = build_machine(where.scene, cpu=cpu)
        enter_frame(machine, where.entry("jsr"))
        return machine
    return build_machine(replace(where.scene, start_line=where.line, start_cycle=where.cycle), cpu=cpu)
