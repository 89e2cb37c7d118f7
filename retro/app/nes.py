"""What `retro nes` does, as a function: load an NES scene, predict its sprite-zero hit, draw it."""

from __future__ import annotations

from pathlib import Path

from retro.chips.ppu.hit import SpriteZeroHit, sprite_zero_hit
from retro.errors import InputError
from retro.scenes import load_scene
from retro.scenes.nes import NesScene

MAX_SCALE = 16


def check_scene(path: str | Path, png: str | Path | None = None, scale: int = 2) -> SpriteZeroHit:
    """The sprite-zero hit of the scene at path; with png, also write its picture there."""
    if not 1 <= scale <= MAX_SCALE:
        raise InputError(f"--scale: {scale} is out of range 1..{MAX_SCALE}")
    scene = load_scene(path)
    if not isinstance(scene, NesScene):
        raise InputError(f"{path}: chip: expected 'nes' for `retro nes`")
    state = scene.ppu_state()
    result = sprite_zero_hit(state)
    if png is not None:
        from retro.render.images import save_png
        from retro.render.nes_image import sprite_zero_image
        save_png(sprite_zero_image(state, result, scale), png)
    return result


def describe(result: SpriteZeroHit) -> str:
    if not result.hit:
        return f"no sprite-zero hit: {result.reason}"
    return (f"sprite-zero hit at pixel x={result.x}, line {result.line}: $2002 bit 6 set at line {result.line} "
            f"dot {result.dot}, {result.dots_after_vblank} PPU dots ({result.cpu_cycles_after_vblank:g} CPU cycles) "
            f"after the vblank flag (line 241 dot 1)")
