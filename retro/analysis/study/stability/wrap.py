"""Coordinate wrap: software box tests against what the VIC-II shows near X = 255/256 and the
right end of the 9-bit X range.

Two full (every pixel opaque) sprites on the same raster lines, sprite a at X = xa and sprite b at
X = xb, for every xa, xb in 0..511. The hardware's answer comes from the VIC-II model's placement
of each sprite (retro.chips.vic.model.placement: on the PAL 6569 the X coordinates $1F8-$1FF do not
exist, so a sprite there never shows, and a sprite near the right end continues at X = 0). The
software tests are the box overlap |xa - xb| < 24 computed
- on 8 bits, as a program that ignores $D010 does (x & $FF),
- on 9 bits without wrap, as the aabb_sprite routine does (asm/ header: exact across 255/256).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.chips.vic.constants import (
    NTSC,
    PAL,
    REG_SPRITE_ENABLE,
    REGISTER_COUNT,
    SPRITE_BYTES,
    SPRITE_COUNT,
    SPRITE_WIDTH,
    Video,
)
from retro.chips.vic.model import VicState, placement
from retro.chips.vic.sprite_registers import set_sprite_x

X_RANGE = 512  # 9-bit sprite X: 0..511 can be written to $D000/$D010

# categories in the wrap maps
AGREE_MISS, AGREE_HIT, SOFTWARE_ONLY, HARDWARE_ONLY = 0, 1, 2, 3


def _occupancy(video: Video) -> np.ndarray:
    """[X register value, screen X coordinate]: where a full sprite at that X puts pixels (model)."""
    registers = bytearray(REGISTER_COUNT)
    registers[REG_SPRITE_ENABLE] = 1
    data = (b"\xff" * SPRITE_BYTES,) + (bytes(SPRITE_BYTES),) * (SPRITE_COUNT - 1)
    occ = np.zeros((X_RANGE, X_RANGE), dtype=bool)
    for x in range(X_RANGE):
        set_sprite_x(registers, 0, x)
        place = placement(VicState(video=video, registers=bytes(registers), sprite_data=data), 0)
        if place is not None:
            occ[x, place.xs] = True
    return occ


def hardware_overlap(video: Video) -> np.ndarray:
    """[xa, xb]: the two full sprites (same lines) share a displayed pixel: $D01E would say so."""
    occ = _occupancy(video).astype(np.int32)
    return (occ @ occ.T) > 0


def software_overlap(bits: int) -> np.ndarray:
    xs = np.arange(X_RANGE) & ((1 << bits) - 1)
    return np.abs(xs[:, None] - xs[None, :]) < SPRITE_WIDTH


def categories(software: np.ndarray, hardware: np.ndarray) -> np.ndarray:
    out = np.full(software.shape, AGREE_MISS, dtype=np.uint8)
    out[software & hardware] = AGREE_HIT
    out[software & ~hardware] = SOFTWARE_ONLY
    out[~software & hardware] = HARDWARE_ONLY
    return out


@dataclass(frozen=True)
class WrapRow:
    video: str
    test: str
    cases: int
    software_only: int  # software says hit, the chip shows no overlap
    hardware_only: int  # the chip latches a collision the software test misses
    example_software_only: tuple[int, int] | None
    example_hardware_only: tuple[int, int] | None


def _example(mask: np.ndarray) -> tuple[int, int] | None:
    found = np.argwhere(mask)
    return None if found.size == 0 else (int(found[0][0]), int(found[0][1]))


def wrap_table() -> tuple[list[WrapRow], dict[tuple[str, str], np.ndarray]]:
    rows, maps = [], {}
    for video in (PAL, NTSC):
        hardware = hardware_overlap(video)
        for bits, name in ((8, "8-bit X (ignores $D010)"), (9, "9-bit X, no wrap (aabb_sprite)")):
            cat = categories(software_overlap(bits), hardware)
            maps[(video.name, name)] = cat
            rows.append(WrapRow(video.name, name, cat.size, int((cat == SOFTWARE_ONLY).sum()),
                                int((cat == HARDWARE_ONLY).sum()), _example(cat == SOFTWARE_ONLY),
                                _example(cat == HARDWARE_ONLY)))
    return rows, maps
