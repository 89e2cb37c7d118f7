"""A sprite's place and colours in a VIC-II register image ($D000 at index 0), read and written in one
place: X is 9 bits, the low byte at $D000 + 2n and bit 8 in bit n of $D010; Y is $D001 + 2n; the
colours are the sprite's own ($D027 + n), the two shared multicolours ($D025, $D026) and the
background ($D021). Source: the C64 Programmer's Reference Guide, chapter 3 (sprite registers)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from retro.chips.vic.constants import (
    COLOR_MASK,
    REG_BACKGROUND0,
    REG_SPRITE_COLOR0,
    REG_SPRITE_MC0,
    REG_SPRITE_MC1,
    REG_SPRITE_X0,
    REG_SPRITE_X_MSB,
)


def sprite_x(registers: Sequence[int], n: int) -> int:
    """Sprite n's 9-bit X."""
    return registers[REG_SPRITE_X0 + 2 * n] | ((registers[REG_SPRITE_X_MSB] >> n) & 1) << 8


def set_sprite_x(registers: bytearray, n: int, x: int) -> None:
    """Put a 9-bit X (0..511) for sprite n: its low byte and its bit 8 in $D010, the other bits kept."""
    bit = 1 << n
    registers[REG_SPRITE_X0 + 2 * n] = x & 0xFF
    registers[REG_SPRITE_X_MSB] = (registers[REG_SPRITE_X_MSB] & ~bit) | (bit if x >> 8 & 1 else 0)


class SpriteColourNumbers(NamedTuple):
    """The colour numbers (0-15) a sprite's pixels show in: pixel value 00 is transparent (the
    background shows), 01 multicolour 0, 10 the sprite's own colour, 11 multicolour 1."""

    background: int
    multicolor0: int
    own: int
    multicolor1: int


def sprite_colours(registers: Sequence[int], n: int) -> SpriteColourNumbers:
    return SpriteColourNumbers(registers[REG_BACKGROUND0] & COLOR_MASK, registers[REG_SPRITE_MC0] & COLOR_MASK,
                               registers[REG_SPRITE_COLOR0 + n] & COLOR_MASK, registers[REG_SPRITE_MC1] & COLOR_MASK)
