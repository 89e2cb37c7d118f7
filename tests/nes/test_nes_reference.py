"""The model against a slow, literal reference written from the nesdev wiki's register-level
description ("PPU scrolling": v/t/x, coarse X increment, Y increment; "PPU OAM"; "PPU rendering"),
pixel by pixel in plain Python, on seeded random scenes."""

from __future__ import annotations

import os
import random

from nes_scenes import random_scene

from retro.chips.ppu.hit import sprite_zero_hit

SCENES = 2000 if os.environ.get("RETRO_EXHAUSTIVE") == "1" else 300
PAGES = {"horizontal": (0, 0, 1, 1), "vertical": (0, 1, 0, 1), "single": (0, 0, 0, 0)}


def pattern(chr_data: bytes, table: int, tile: int, row: int, col: int) -> int:
    address = table * 0x1000 + tile * 16 + row
    return ((chr_data[address] >> (7 - col)) & 1) | (((chr_data[address + 8] >> (7 - col)) & 1) << 1)


def increment_y(v: int) -> int:
    if (v & 0x7000) != 0x7000:
        return v + 0x1000
    v &= ~0x7000
    y = (v & 0x03E0) >> 5
    if y == 29:
        y = 0
        v ^= 0x0800
    elif y == 31:
        y = 0
    else:
        y += 1
    return (v & ~0x03E0) | (y << 5)


def increment_x(v: int) -> int:
    if (v & 0x001F) == 31:
        return (v & ~0x001F) ^ 0x0400
    return v + 1


def reference_hit(state):
    t = ((state.ctrl & 3) << 10) | (state.scroll_x >> 3) | ((state.scroll_y >> 3) << 5) | ((state.scroll_y & 7) << 12)
    fine_x = state.scroll_x & 7
    if not (state.mask & 0x08 and state.mask & 0x10):
        return None
    y, tile, attr, sx = state.oam[0:4]
    tall = bool(state.ctrl & 0x20)
    height = 16 if tall else 8
    v = t
    for line in range(240):
        v = (v & ~0x041F) | (t & 0x041F)       # dot 257 of the previous line: horizontal bits from t
        row_in_sprite = line - (y + 1)
        if 0 <= row_in_sprite < height:
            src_row = height - 1 - row_in_sprite if attr & 0x80 else row_in_sprite
            if tall:
                table, index = tile & 1, (tile & 0xFE) + (src_row >> 3)
            else:
                table, index = (1 if state.ctrl & 0x08 else 0), tile
            for x in range(sx, min(sx + 8, 256)):
                col = x - sx
                src_col = 7 - col if attr & 0x40 else col
                if pattern(state.chr, table, index, src_row & 7, src_col) == 0:
                    continue
                if x == 255 or (x < 8 and (state.mask & 0x06) != 0x06):
                    continue
                w = v
                for _ in range((fine_x + x) // 8):
                    w = increment_x(w)
                nametable = (w >> 10) & 3
                address = PAGES[state.mirroring][nametable] * 0x400 + (w & 0x03FF)
                bg_tile = state.ciram[address]
                bg_table = 1 if state.ctrl & 0x10 else 0
                if pattern(state.chr, bg_table, bg_tile, (w >> 12) & 7, (fine_x + x) % 8):
                    return x, line
        v = increment_y(v)
    return None


def test_model_matches_register_level_reference():
    rng = random.Random(4)
    mismatches = []
    hits = 0
    for number in range(SCENES):
        state = random_scene(rng, mirrorings=("horizontal", "vertical", "single"))
        model = sprite_zero_hit(state)
        got = (model.x, model.line) if model.hit else None
        want = reference_hit(state)
        hits += want is not None
        if got != want:
            mismatches.append((number, got, want))
    assert mismatches == []
    assert hits >= SCENES // 5, "the sample must contain enough hits to mean something"
