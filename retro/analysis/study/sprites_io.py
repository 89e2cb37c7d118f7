"""Sprite files -> shapes for the study, through retro.sprites (the one sprite decoder).

`load_sprite_files` reads a user's sprites into the corpus (`retro chart --sprites FILE`), by content
(retro.sprites.read_sprite_frames), every format `retro` reads sprites from:
- a SpritePad file (.spd: 1.x, 2.0 beta, Pro 4 and 5) or a Spritemate file (.spm): every sprite,
  multicolor as the file says;
- a raw sprite file (64-byte blocks, or one 63-byte sprite; .spr, .bin, .raw, ...): every frame,
  multicolor when the name starts with `mc_` (raw files do not record the mode);
- a PNG sprite or sheet: every sprite, multicolor when the name starts with `mc_` (no scene gives
  colours here, so multicolour pixels are read in the preview colours, see gfx_png_sprites);
- a VIC-II scene (.toml): its enabled sprites with their multicolor and expansion flags.
Fully transparent sprites are left out (they never collide); a file with none left is an error.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from retro import sprites
from retro.errors import InputError

MAX_USER_SPRITES = 64  # the corpus grows with the square of its shapes


def is_multicolor(path: Path) -> bool:
    """Raw .spr files do not record the mode; sprites/ marks multicolor ones by name (`mc_*.spr`,
    see sprites/make_sprites.py)."""
    return path.stem.startswith("mc_")


def sprite_opacity(path: Path, frame: int = 0) -> tuple[np.ndarray, bool, bytes]:
    """(mask [21, 24] bool in screen pixels, multicolor, the 63 bytes) of frame `frame` of a .spr file."""
    multicolor = is_multicolor(path)
    data = sprites.read_spr(path, frame)
    return sprites.opaque_mask(data, multicolor), multicolor, data


def scene_shapes(path: str, minimum: int = 0) -> list[tuple[int, object]]:
    """(sprite index, shape) for each enabled sprite of a VIC-II scene with an opaque pixel."""
    from retro.analysis.study.corpus import Shape
    from retro.chips.vic.constants import (
        REG_SPRITE_ENABLE,
        REG_SPRITE_EXPAND_X,
        REG_SPRITE_EXPAND_Y,
        REG_SPRITE_MULTICOLOR,
        SPRITE_BYTES,
        SPRITE_COUNT,
    )
    from retro.scenes import load_scene
    from retro.scenes.vic import VicScene

    scene = load_scene(path)
    if not isinstance(scene, VicScene):
        raise InputError(f"{path}: chip: a VIC-II scene is needed here (chip = \"vic-ii\")")
    state = scene.state
    stem = Path(path).stem
    shapes = []
    for n in range(SPRITE_COUNT):
        if not state.sprite_flag(REG_SPRITE_ENABLE, n):
            continue
        data = bytes(state.sprite_data[n][:SPRITE_BYTES])
        multicolor = state.sprite_flag(REG_SPRITE_MULTICOLOR, n)
        ex, ey = state.sprite_flag(REG_SPRITE_EXPAND_X, n), state.sprite_flag(REG_SPRITE_EXPAND_Y, n)
        mask = sprites.opaque_mask(data, multicolor)
        if not mask.any():
            continue  # a fully transparent sprite never collides: nothing to choose a method for
        mask = np.repeat(np.repeat(mask, 2 if ey else 1, axis=0), 2 if ex else 1, axis=1)
        name = f"sprite{n}" if minimum else f"{stem}.sprite{n}"
        shapes.append((n, Shape(name=name, mask=mask, multicolor=multicolor, source=f"{path} sprite {n}",
                                data=data, expand_x=ex, expand_y=ey)))
    if len(shapes) < minimum:
        raise InputError(f"{path}: sprite: need at least {minimum} enabled sprites with opaque pixels "
                         f"(found {len(shapes)})")
    return shapes


def _file_frames(path: Path) -> list[tuple[str, bytes, bool]]:
    """(name, 63 bytes, multicolor) for every sprite of a sprite file."""
    found = sprites.read_sprite_frames(path, multicolor=is_multicolor(path))
    return [(f"{path.stem}.{i}" if len(found) > 1 else path.stem, frame.data,
             is_multicolor(path) if frame.multicolor is None else frame.multicolor)
            for i, frame in enumerate(found)]


def load_sprite_file(path_text: str) -> list:
    """The shapes of one sprite file (see the module docstring)."""
    from retro.analysis.study.corpus import Shape

    path = Path(path_text)
    if path.suffix.lower() == ".toml":
        return [shape for _, shape in scene_shapes(path_text)]
    shapes = []
    for name, data, multicolor in _file_frames(path):
        mask = sprites.opaque_mask(data, multicolor)
        if mask.any():
            shapes.append(Shape(name=name, mask=mask, multicolor=multicolor, source=str(path), data=bytes(data)))
    if not shapes:
        raise InputError(f"{path}: every sprite in the file is transparent: nothing can collide")
    return shapes


def load_sprite_files(paths, taken: set[str] = frozenset()) -> list:
    """Every shape of every file, names made unique (a clash gets `#2`, `#3`, ...)."""
    from dataclasses import replace

    names = set(taken)
    out = []
    for path in dict.fromkeys(str(p) for p in paths):
        for shape in load_sprite_file(path):
            name, n = shape.name, 2
            while name in names:
                name, n = f"{shape.name}#{n}", n + 1
            names.add(name)
            out.append(replace(shape, name=name))
            if len(out) > MAX_USER_SPRITES:
                raise InputError(f"{path}: more than {MAX_USER_SPRITES} sprites given with --sprites (the corpus "
                                 "grows with the square of its sprites)")
    return out
