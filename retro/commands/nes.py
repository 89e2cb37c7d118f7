"""`retro nes`: load an NES scene, predict its sprite-zero hit and sprite overflow, draw the hit."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.chips.ppu.constants import VBLANK_LINE, VBLANK_DOT
from retro.chips.ppu.hit import SpriteZeroHit, sprite_zero_hit
from retro.chips.ppu.overflow import SpriteOverflow, sprite_overflow
from retro.errors import InputError
from retro.fileio import all_or_nothing, file_option
from retro.numbers import parse_int
from retro.scenes import load_scene
from retro.scenes.nes import NesScene
import argparse
from retro.commands import options

MAX_SCALE = 16


@dataclass(frozen=True)
class NesRun:
    scene: NesScene
    hit: SpriteZeroHit
    overflow: SpriteOverflow
    png: Path | None  # the picture written, if one was asked for


@all_or_nothing
def nes(path: str | Path, *, png: str | Path | None = None, scale: int | str = 2) -> NesRun:
    """The sprite-zero hit of the scene at path; with png, also write its picture there."""
    scale = parse_int(scale, field="--scale", lo=1, hi=MAX_SCALE)
    file_option(png, "--png")
    scene = load_scene(path)
    if not isinstance(scene, NesScene):
        raise InputError(f"{path}: chip: expected 'nes' for `retro nes`")
    state = scene.ppu_state()
    result = sprite_zero_hit(state)
    written = None
    if png is not None:
        from retro.render.images import save_png
        from retro.render.nes_image import sprite_zero_image
        written = save_png(sprite_zero_image(state, result, scale), png)
    return NesRun(scene, result, sprite_overflow(state), written)


def as_json(run: NesRun) -> dict:
    """The object `retro nes --json` prints (its keys are a contract)."""
    return {**run.hit.as_json(), "sprite_overflow": run.overflow.as_json()}


def lines(run: NesRun) -> list[str]:
    return [_describe(run.hit), _describe_overflow(run.overflow)] + ([f"wrote {run.png}"] if run.png is not None else [])


def _describe_overflow(result: SpriteOverflow) -> str:
    if not result.set:
        return f"no sprite overflow: {result.reason}"
    what = (f"{result.sprites_on_line} sprites on the line" if result.sprites_on_line > 8
            else f"a false overflow: {result.sprites_on_line} sprites on the line, the evaluation bug reads another byte as a Y")
    return (f"sprite overflow: $2002 bit 5 set at line {result.line} dot {result.dot}, {result.dots_after_vblank} PPU "
            f"dots after the vblank flag ({what})")


def _describe(result: SpriteZeroHit) -> str:
    if not result.hit:
        return f"no sprite-zero hit: {result.reason}"
    return (f"sprite-zero hit at pixel x={result.x}, line {result.line}: $2002 bit 6 set at line {result.line} "
            f"dot {result.dot}, {result.dots_after_vblank} PPU dots ({result.cpu_cycles_after_vblank:g} CPU cycles) "
            f"after the vblank flag (line {VBLANK_LINE} dot {VBLANK_DOT})")


# The command line: this command's options and how it runs from them.

HELP = "predict the NES sprite-zero hit ($2002 bit 6) of a scene: pixel, line, dot"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", metavar="SCENE.toml")
    p.add_argument("--json", action="store_true", help="print one JSON object: hit, line, dot, x, dots_after_vblank, "
                                                       "cpu_cycles_after_vblank")
    p.add_argument("--png", metavar="OUT.png", help="write a picture of the frame and sprite 0")
    options.scale(p, "picture", MAX_SCALE)


def main(args: argparse.Namespace) -> int:
    result = nes(args.scene, png=args.png, scale=args.scale)
    options.show(lines, as_json if args.json else None, result)
    return 0
