"""Random NES scenes for the cross-checks (seeded): PpuState values with varied rules in play."""

from __future__ import annotations

import random

from retro.chips.ppu.constants import CHR_SIZE, CIRAM_SIZE, NTSC, OAM_SIZE, TILE_BYTES
from retro.chips.ppu.state import PpuState

OPAQUE_TILES = range(1, 16)      # tiles 1-15 of both tables get random pixels; tile 0 stays empty


def random_chr(rng: random.Random) -> bytes:
    data = bytearray(CHR_SIZE)
    for table in (0, 1):
        for tile in OPAQUE_TILES:
            density = rng.choice((0.15, 0.4, 0.8, 1.0))
            base = table * 0x1000 + tile * TILE_BYTES
            for row in range(8):
                for col in range(8):
                    if rng.random() < density:
                        value = rng.randint(1, 3)
                        bit = 0x80 >> col
                        data[base + row] |= bit if value & 1 else 0
                        data[base + row + 8] |= bit if value & 2 else 0
    return bytes(data)


def random_scene(rng: random.Random, mirrorings=("horizontal", "vertical")) -> PpuState:
    ctrl = rng.randint(0, 3) | rng.choice((0, 0x08)) | rng.choice((0, 0x10)) | rng.choice((0, 0, 0x20))
    mask = 0x1E
    roll = rng.random()
    if roll < 0.15:
        mask &= ~rng.choice((0x02, 0x04, 0x06))          # left column hidden
    elif roll < 0.2:
        mask &= ~rng.choice((0x08, 0x10))                # one layer off
    mask |= rng.choice((0, 0x01, 0x20, 0xE0))            # greyscale / emphasis: irrelevant
    density = rng.choice((0.1, 0.3, 0.6))
    ciram = bytes(rng.choice(OPAQUE_TILES) if rng.random() < density else 0 for _ in range(CIRAM_SIZE))
    oam = bytearray(rng.randrange(256) for _ in range(OAM_SIZE))   # other sprites: random, never count
    y = rng.choice((rng.randint(0, 255), rng.randint(0, 238), rng.randint(230, 245)))
    x = rng.choice((rng.randint(0, 255), rng.randint(0, 12), rng.randint(244, 255)))
    tile = rng.choice(OPAQUE_TILES) if rng.random() < 0.85 else rng.randrange(256)
    oam[0:4] = bytes([y, tile, rng.randrange(256), x])
    return PpuState(ctrl=ctrl, mask=mask, scroll_x=rng.randrange(256),
                    scroll_y=rng.choice((rng.randrange(240), rng.randrange(256))),
                    mirroring=rng.choice(mirrorings), video=NTSC, oam=bytes(oam), chr=random_chr(rng), ciram=ciram)
