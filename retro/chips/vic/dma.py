"""When the VIC-II takes the bus from the CPU: Bad Lines and sprite DMA -> the BA line per cycle.

Rules [Bauer 3.5, 3.6.3, 3.8.1; the timing diagrams of 3.6.3]:
- A Bad Line is a line in $30-$F7 whose low three bits equal YSCROLL ($D011 bits 0-2) while DEN
  ($D011 bit 4) is set (the DEN the device sampled in line $30: device.VicDevice._latch). Its c-accesses take cycles 15-54 on all three chips; BA is low from cycle 12
  (BA_LEAD earlier).
- Sprite n whose row is shown on line D fetches it in the line before: its two s-accesses take
  cycles sprite0_fetch_cycle + 2n and the next one, counted from line D-1 (6569: 58-59 for sprite 0,
  60-61 sprite 1, 62-63 sprite 2, then cycles 1-10 of line D for sprites 3-7; 6567R56A: 59-60 for
  sprite 0, 61-62, 63-64, then cycles 1-10 for sprites 3-7; 6567R8: 59-60 for sprite 0, 61-62,
  63-64, 65 and 1 of line D for sprite 3, then cycles 2-9 for sprites 4-7). BA is low from BA_LEAD cycles
  before. An expanded sprite fetches on all 42 lines. (The 6567R8's cycle: VICE-testprogs
  VICII/spritesteal on real 6567R8s, docs/vic.md "Sprite DMA cycle".)
- The CPU stops at its first read cycle while BA is low and goes on when BA is high again; it never
  stops in a write cycle (the machine applies this: retro.cpu.mpu).
Between two sprites' DMA BA stays low when their BA windows touch (sprites 0 and 2 without 1 cost
as much as 0, 1 and 2).

Simplification, stated: each register state is taken as if it held all frame (as in the collision
model); a $D011 write that makes or unmakes a Bad Line in the middle of a line moves BA from the
next cycle on, which covers the common cases (FLD, a Bad Line forced late) but not the partial-row
effects of forcing one after cycle 14.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from retro.chips.vic.constants import (
    BA_LEAD,
    BAD_LINE_FIRST_STOLEN,
    BAD_LINE_LAST,
    BAD_LINE_LAST_STOLEN,
    CONTROL1_DEN,
    CONTROL1_YSCROLL,
    GRAPHICS_FIRST_LINE,
    REG_CONTROL1,
    REG_SPRITE_ENABLE,
    REG_SPRITE_EXPAND_Y,
    REG_SPRITE_Y0,
    SPRITE_COUNT,
    SPRITE_DMA_CYCLES,
    Video,
)
from retro.chips.vic.model import sprite_rows

# Registers whose value changes when the bus is taken
DMA_REGISTERS = (REG_CONTROL1, REG_SPRITE_ENABLE, REG_SPRITE_EXPAND_Y) + tuple(
    REG_SPRITE_Y0 + 2 * n for n in range(SPRITE_COUNT))
_BAD_LINE_BITS = CONTROL1_DEN | CONTROL1_YSCROLL


def is_bad_line(control1: int, line: int) -> bool:
    """Whether `line` is a Bad Line with $D011 = control1 [Bauer 3.5]."""
    return (bool(control1 & CONTROL1_DEN) and GRAPHICS_FIRST_LINE <= line <= BAD_LINE_LAST
            and (line & CONTROL1_YSCROLL) == (control1 & CONTROL1_YSCROLL))


def sprite_fetch_lines(video: Video, y: int, expand_y: bool) -> np.ndarray:
    """Per raster line, whether a sprite at Y = y fetches a row there (the line before it is shown)."""
    shown = sprite_rows(video, y, expand_y) >= 0
    return np.roll(shown, -1)


@dataclass(frozen=True, eq=False)
class BusSchedule:
    """BA for every cycle of a frame, as two lookups indexed by frame time (0-based cycle in the frame).

    wait[t]: cycles from t until BA is high again (0 while BA is high);
    free[t]: cycles from t during which BA stays high (0 while it is low; frame_cycles if never low).
    """

    video: Video
    wait: list[int]
    free: list[int]
    low: np.ndarray  # bool per frame time: BA low


def ba_low(video: Video, registers: bytes) -> np.ndarray:
    """Bool per frame time: whether BA is low in that cycle."""
    cpl = video.cycles_per_line
    low = np.zeros(video.frame_cycles, dtype=bool)
    control1 = registers[REG_CONTROL1]
    if control1 & CONTROL1_DEN:
        first = BAD_LINE_FIRST_STOLEN - BA_LEAD - 1  # 0-based cycle index within the line
        for line in range(GRAPHICS_FIRST_LINE, min(BAD_LINE_LAST, video.lines - 1) + 1):
            if is_bad_line(control1, line):
                low[line * cpl + first:line * cpl + BAD_LINE_LAST_STOLEN] = True
    enabled = registers[REG_SPRITE_ENABLE]
    expanded = registers[REG_SPRITE_EXPAND_Y]
    for n in range(SPRITE_COUNT):
        if not enabled >> n & 1:
            continue
        lines = np.flatnonzero(sprite_fetch_lines(video, registers[REG_SPRITE_Y0 + 2 * n], bool(expanded >> n & 1)))
        first_stolen = lines * cpl + video.sprite0_fetch_cycle + SPRITE_DMA_CYCLES * n - 1
        for offset in range(-BA_LEAD, SPRITE_DMA_CYCLES):
            low[(first_stolen + offset) % video.frame_cycles] = True
    return low


def _distance_to(targets: np.ndarray, size: int) -> np.ndarray:
    """For every t in 0..size-1, cycles from t to the next t' >= t (circularly) where targets[t'] is True."""
    where = np.flatnonzero(targets)
    if where.size == 0:
        return np.full(size, size, dtype=np.int64)
    doubled = np.concatenate([where, where + size])
    t = np.arange(size)
    return doubled[np.searchsorted(doubled, t)] - t


@lru_cache(maxsize=64)
def _schedule(video: Video, key: bytes) -> BusSchedule:
    registers = bytearray(max(DMA_REGISTERS) + 1)
    for register, value in zip(DMA_REGISTERS, key):
        registers[register] = value
    low = ba_low(video, bytes(registers))
    wait = _distance_to(~low, video.frame_cycles)
    free = _distance_to(low, video.frame_cycles)
    low.flags.writeable = False
    return BusSchedule(video, wait.tolist(), free.tolist(), low)


def bus_schedule(video: Video, registers: bytes) -> BusSchedule:
    """The BA schedule of a register state (cached on the registers that matter)."""
    key = bytes(registers[r] & (_BAD_LINE_BITS if r == REG_CONTROL1 else 0xFF) for r in DMA_REGISTERS)
    return _schedule(video, key)

