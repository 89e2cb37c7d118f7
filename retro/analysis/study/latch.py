"""The hardware latch method: what the VIC-II model (retro.chips.vic) puts in $D01E for each case.

Each case places shape a as sprite 0 at (BASE_X, BASE_Y) and shape b as sprite 1 at
(BASE_X + dx, BASE_Y + dy), both enabled, on a PAL 6569, and runs the model for one frame. The
method reports a hit when both bits 0 and 1 are set: with only two sprites that is the pair's
answer. What it cannot tell with more sprites (which pair) or over time (which frame) is shown by
the latch-pitfalls part of the stability study.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from retro.analysis.study.corpus import Pair, Shape
from retro.chips.vic.constants import (
    PAL,
    REG_SPRITE_ENABLE,
    REG_SPRITE_EXPAND_X,
    REG_SPRITE_EXPAND_Y,
    REG_SPRITE_MULTICOLOR,
    REG_SPRITE_Y0,
    REGISTER_COUNT,
    SPRITE_BYTES,
    SPRITE_COUNT,
)
from retro.chips.vic.model import VicState, frame_collisions
from retro.chips.vic.sprite_registers import set_sprite_x

BASE_X = 100  # both sprites well inside the 9-bit X range and the frame: no wrap (see stability.wrap)
BASE_Y = 100
PAIR_BITS = 0b11  # sprites 0 and 1


def sprite_bytes(shape: Shape) -> bytes:
    """The shape's sprite data: from its file, or encoded from a hires 24x21 mask."""
    if shape.data is not None:
        return shape.data
    from retro.sprites import encode

    return encode(shape.mask.astype(np.uint8))


def sprites_state(placed: list[tuple[Shape, int, int]], video=PAL) -> VicState:
    """A VIC-II state with sprite n = placed[n] (shape, x, y) enabled, the other sprites off."""
    registers = bytearray(REGISTER_COUNT)
    data = [bytes(SPRITE_BYTES)] * SPRITE_COUNT
    for n, (shape, x, y) in enumerate(placed):
        set_sprite_x(registers, n, x)
        registers[REG_SPRITE_Y0 + 2 * n] = y & 0xFF
        registers[REG_SPRITE_ENABLE] |= 1 << n
        registers[REG_SPRITE_MULTICOLOR] |= shape.multicolor << n
        registers[REG_SPRITE_EXPAND_X] |= shape.expand_x << n
        registers[REG_SPRITE_EXPAND_Y] |= shape.expand_y << n
        data[n] = sprite_bytes(shape)
    return VicState(video=video, registers=bytes(registers), sprite_data=tuple(data))


def two_sprite_state(a: Shape, b: Shape, ax: int, ay: int, bx: int, by: int, video=PAL) -> VicState:
    return sprites_state([(a, ax, ay), (b, bx, by)], video)


def case_state(pair: Pair, dx: int, dy: int) -> VicState:
    return two_sprite_state(pair.a, pair.b, BASE_X, BASE_Y, BASE_X + dx, BASE_Y + dy)


def frame_latch(pair: Pair, dx: int, dy: int) -> int:
    """$D01E after one frame of the case."""
    return frame_collisions(case_state(pair, dx, dy)).d01e


def latch_verdicts(pair: Pair) -> np.ndarray:
    out = np.empty(pair.cases, dtype=float)
    for i, (dx, dy) in enumerate(zip(pair.dx.tolist(), pair.dy.tolist())):
        out[i] = frame_latch(pair, dx, dy) & PAIR_BITS == PAIR_BITS
    return out


class _Slot:
    """A bus device that forwards to whichever VicDevice is current (the bus maps a range once)."""

    def __init__(self) -> None:
        self.current = None

    def read(self, address: int, cycle: int) -> int:
        return self.current.read(address, cycle)

    def write(self, address: int, value: int, cycle: int) -> None:
        self.current.write(address, value, cycle)

    def peek(self, address: int) -> int:
        return self.current.peek(address)


def latch_machine(program) -> tuple[object, Callable[[Pair, int], None]]:
    """A machine with the program loaded and a VIC-II device at $D000-$D3FF, and a function that
    sets the device up for case `index` of a pair with one whole frame already drawn (so a read of
    $D01E returns that frame's bits)."""
    from retro.chips.vic.device import VicDevice
    from retro.machines.c64 import build_c64

    slot = _Slot()
    machine = build_c64(vic=slot)
    machine.load(program)

    def prepare(pair: Pair, index: int) -> None:
        state = case_state(pair, int(pair.dx[index]), int(pair.dy[index]))
        slot.current = VicDevice(state, start_cycle=machine.cycle - state.video.frame_cycles)

    return machine, prepare
