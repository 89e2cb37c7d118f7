"""The VIC-II collision model: one frame of a register state -> $D01E/$D01F events with numpy masks.

Rules [Bauer 3.8.1-3.8.2, PRG p.145]:
- Sprite n's row r is drawn on the raster line after the one whose low 8 bits equal its Y (the
  compare is 8-bit, so a small Y matches again on lines 256+ where they exist), rows on successive
  lines (two lines each with Y expansion). A match while the sprite's DMA is still running is
  ignored. The state is taken as steady (it held in the previous frame too), so a sprite that runs
  past the last line continues at the top of the frame.
- Pixel i of a row sits at X + i (X + 2i, X + 2i + 1 expanded); X is 9 bits; X coordinates wrap
  after the last one that exists ($1F7 on the 6569, so a sprite at $1F8-$1FF never shows; $1FF on the
  6567R8). Hires `1` and multicolor `01`, `10`, `11` are opaque.
- $D01E: every sprite with an opaque pixel where another enabled sprite has one, anywhere in the
  frame (border and off-screen included). Disabled sprites never collide; priority does not matter.
- $D01F: a sprite's opaque pixel over a foreground pixel (graphics.foreground), nowhere in the
  vertical border.
The background is decoded only at the sprites' opaque pixels.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from retro.chips.vic.beam import beam_key, pixel_time
from retro.chips.vic.constants import (
    CONTROL1_RST8,
    IRQ_ANY,
    IRQ_RASTER,
    IRQ_SOURCES,
    IRQ_SPRITE_BACKGROUND,
    IRQ_SPRITE_SPRITE,
    RASTER_IRQ_LINE0_DELAY,
    REG_CONTROL1,
    REG_CONTROL2,
    REG_IRQ_ENABLE,
    REG_IRQ_LATCH,
    REG_RASTER,
    REG_SPRITE_ENABLE,
    REG_SPRITE_EXPAND_X,
    REG_SPRITE_EXPAND_Y,
    REG_SPRITE_MULTICOLOR,
    REG_SPRITE_X0,
    REG_SPRITE_X_MSB,
    REG_SPRITE_Y0,
    REGISTER_COUNT,
    SPRITE_BYTES,
    SPRITE_COUNT,
    SPRITE_HEIGHT,
    UNUSED_BITS,
    Y_COMPARE_MASK,
    Video,
)
from retro.chips.vic.graphics import VicMemory, foreground_points
from retro.sprites import opaque_mask

# Registers whose value changes what collides (the device recomputes its schedule when they change)
COLLISION_REGISTERS = (tuple(range(REG_SPRITE_X0, REG_SPRITE_X_MSB + 1))
                       + (REG_CONTROL1, REG_SPRITE_ENABLE, REG_CONTROL2, REG_SPRITE_EXPAND_Y,
                          REG_SPRITE_MULTICOLOR, REG_SPRITE_EXPAND_X))
FIRST_SPRITE_ROW_LINE_OFFSET = 1  # row 0 is on the line after the Y match
STEADY_STATE_FRAMES = 3


@dataclass(frozen=True, eq=False)
class VicState:
    """Everything one frame depends on: chip, register values (as written), sprite data, memory."""

    video: Video
    registers: bytes  # REGISTER_COUNT values as last written
    sprite_data: tuple[bytes, ...]  # SPRITE_COUNT x 63 bytes
    memory: VicMemory = field(default_factory=VicMemory.blank)

    def __post_init__(self) -> None:
        if len(self.registers) != REGISTER_COUNT or len(self.sprite_data) != SPRITE_COUNT:
            raise ValueError("VicState needs 47 registers and 8 sprites")

    def with_registers(self, registers: bytes) -> "VicState":
        return replace(self, registers=bytes(registers))

    def collision_key(self) -> bytes:
        return bytes(self.registers[r] for r in COLLISION_REGISTERS)

    def sprite_x(self, n: int) -> int:
        return self.registers[REG_SPRITE_X0 + 2 * n] | ((self.registers[REG_SPRITE_X_MSB] >> n) & 1) << 8

    def sprite_y(self, n: int) -> int:
        return self.registers[REG_SPRITE_Y0 + 2 * n]

    def sprite_flag(self, register: int, n: int) -> bool:
        return bool((self.registers[register] >> n) & 1)


@dataclass(frozen=True)
class Placement:
    """Where one sprite's opaque pixels fall in the frame: mask[i, j] at (lines[i], xs[j])."""

    sprite: int
    lines: np.ndarray
    xs: np.ndarray
    mask: np.ndarray  # (len(lines), len(xs)) bool


@dataclass(frozen=True)
class FrameCollisions:
    """The collision events of one frame of a state.

    For each latch: the frame times (sorted, unique) at which some overlap pixel is drawn and the
    OR of the sprite bits set at each; the overlap pixels themselves (for images); the first one.
    """

    video: Video
    ss_times: np.ndarray
    ss_bits: np.ndarray
    sb_times: np.ndarray
    sb_bits: np.ndarray
    ss_pixels: tuple[np.ndarray, np.ndarray]  # (lines, xs)
    sb_pixels: tuple[np.ndarray, np.ndarray]
    first_ss: tuple[int, int] | None
    first_sb: tuple[int, int] | None
    pairs: tuple[tuple[int, int], ...]
    ss_pixel_bits: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint8))  # sprites at each ss pixel
    sb_pixel_bits: np.ndarray = field(default_factory=lambda: np.zeros(0, np.uint8))  # the sprite at each sb pixel

    @property
    def d01e(self) -> int:
        return int(np.bitwise_or.reduce(self.ss_bits)) if self.ss_bits.size else 0

    @property
    def d01f(self) -> int:
        return int(np.bitwise_or.reduce(self.sb_bits)) if self.sb_bits.size else 0


@lru_cache(maxsize=2048)
def sprite_rows(video: Video, y: int, expand_y: bool) -> np.ndarray:
    """Row of the sprite shown on each raster line (-1: none) in the steady state, for Y = y.

    DMA starts at a line whose low 8 bits equal y, unless the sprite's DMA is still on from an
    earlier start [Bauer 3.8.1]; the display runs 21 rows (42 lines expanded) and may cross into the
    next frame. Simulated over a few frames; the last one is the steady state.
    """
    repeat = 2 if expand_y else 1
    height = SPRITE_HEIGHT * repeat
    total = STEADY_STATE_FRAMES * video.lines
    rows = np.full(total + height + 1, -1, dtype=np.int16)
    free_from = 0
    for line in range(total):
        if (line % video.lines) & Y_COMPARE_MASK == y and line >= free_from:
            start = line + FIRST_SPRITE_ROW_LINE_OFFSET
            rows[start:start + height] = np.arange(height) // repeat
            free_from = line + height
    steady = rows[total - video.lines:total].copy()
    steady.flags.writeable = False
    return steady


@lru_cache(maxsize=512)
def _sprite_shape(data: bytes, multicolor: bool, expand_x: bool) -> np.ndarray:
    mask = opaque_mask(data, multicolor)
    return np.repeat(mask, 2, axis=1) if expand_x else mask


@dataclass(frozen=True)
class _Placed:
    """Placement arrays of one sprite plus its opaque pixels listed row-major (lines[i], xs[j] order)."""

    lines: np.ndarray
    xs: np.ndarray
    mask: np.ndarray
    pixel_lines: np.ndarray
    pixel_xs: np.ndarray


# Keyed on everything a sprite's pixels depend on, so a device or loop that keeps a sprite still
# (or returns it to a place) pays for its placement once.
@lru_cache(maxsize=4096)
def _placed(video: Video, x: int, y: int, expand_y: bool, data: bytes, multicolor: bool, expand_x: bool) -> _Placed:
    rows = sprite_rows(video, y, expand_y)
    lines = np.flatnonzero(rows >= 0)
    shape = _sprite_shape(data, multicolor, expand_x)
    xs = (x + np.arange(shape.shape[1])) % video.x_positions
    mask = shape[rows[lines]]
    i, j = np.nonzero(mask)
    placed = _Placed(lines, xs, mask, lines[i], xs[j])
    for array in vars(placed).values():
        array.flags.writeable = False  # shared through the cache: nobody may change them
    return placed


def _placed_sprite(state: VicState, n: int) -> _Placed | None:
    video = state.video
    x = state.sprite_x(n)
    if not state.sprite_flag(REG_SPRITE_ENABLE, n) or x >= video.x_positions:
        return None
    return _placed(video, x, state.sprite_y(n), state.sprite_flag(REG_SPRITE_EXPAND_Y, n),
                   bytes(state.sprite_data[n][:SPRITE_BYTES]), state.sprite_flag(REG_SPRITE_MULTICOLOR, n),
                   state.sprite_flag(REG_SPRITE_EXPAND_X, n))


def placement(state: VicState, n: int) -> Placement | None:
    """Sprite n's pixels in the frame, or None when it shows nowhere (disabled, X in the gap).

    The arrays are shared with a cache and read-only."""
    placed = _placed_sprite(state, n)
    return None if placed is None else Placement(n, placed.lines, placed.xs, placed.mask)


def _opaque_pixels(state: VicState) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lines, xs, sprite bit) of every opaque pixel of every shown sprite, by sprite then row-major.

    That order is the order in which the pixel lists of FrameCollisions are reported.
    """
    shown = [(n, placed) for n in range(SPRITE_COUNT)
             if (placed := _placed_sprite(state, n)) is not None and placed.pixel_lines.size]
    if not shown:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.uint8)
    lines = np.concatenate([placed.pixel_lines for _, placed in shown]).astype(np.int64, copy=False)
    xs = np.concatenate([placed.pixel_xs for _, placed in shown]).astype(np.int64, copy=False)
    bits = np.repeat(np.array([1 << n for n, _ in shown], np.uint8), [placed.pixel_lines.size for _, placed in shown])
    return lines, xs, bits


def _lower_sprites_under(video: Video, lines: np.ndarray, xs: np.ndarray, bits: np.ndarray) -> np.ndarray:
    """For each opaque pixel, the OR of the bits of lower-numbered sprites opaque at the same place.

    A sprite has at most one pixel per place and each bit is one sprite, so OR-ing all bits per
    place and keeping those below the pixel's own bit gives what a canvas drawn sprite 0, 1, ...
    would hold when the pixel's sprite is drawn. For the same reason the OR is a sum of distinct
    powers of two, and np.add.at is about twice as fast as np.bitwise_or.at.
    """
    places = lines * video.x_positions + xs
    canvas = np.zeros(video.lines * video.x_positions, np.uint8)
    np.add.at(canvas, places, bits)
    return canvas[places] & (bits - 1)


def _pairs(bit_sets: np.ndarray) -> tuple[tuple[int, int], ...]:
    found = set()
    for value in np.flatnonzero(np.bincount(bit_sets, minlength=1)).tolist():  # distinct sets, no sort needed
        members = [n for n in range(SPRITE_COUNT) if value >> n & 1]
        found.update((a, b) for i, a in enumerate(members) for b in members[i + 1:])
    return tuple(sorted(found))


def _events(video: Video, lines: np.ndarray, xs: np.ndarray, bits: np.ndarray):
    if lines.size == 0:
        empty = np.zeros(0, np.int64)
        return empty, np.zeros(0, np.uint8), None
    times = pixel_time(video, lines, xs)
    order = np.argsort(times, kind="stable")  # the pixels come nearly in time order: a cheap sort
    times, bits = times[order], bits[order]
    start = np.flatnonzero(np.concatenate(([True], times[1:] != times[:-1])))  # first of each time
    merged = np.bitwise_or.reduceat(bits, start).astype(np.uint8)
    first = int(np.argmin(beam_key(video, lines, xs)))
    return times[start], merged, (int(lines[first]), int(xs[first]))


def frame_collisions(state: VicState) -> FrameCollisions:
    """All sprite-sprite and sprite-background overlap events of one frame of state."""
    video = state.video
    lines, xs, bits = _opaque_pixels(state)
    under = _lower_sprites_under(video, lines, xs, bits)
    ss = under != 0
    ssl, ssx, ssb = lines[ss], xs[ss], under[ss] | bits[ss]
    sb = foreground_points(video, state.memory, state.registers[REG_CONTROL1], state.registers[REG_CONTROL2],
                           lines, xs)
    sbl, sbx, sbb = lines[sb], xs[sb], bits[sb]
    ss_times, ss_merged, first_ss = _events(video, ssl, ssx, ssb)
    sb_times, sb_merged, first_sb = _events(video, sbl, sbx, sbb)
    return FrameCollisions(video, ss_times, ss_merged, sb_times, sb_merged, (ssl, ssx), (sbl, sbx),
                           first_ss, first_sb, _pairs(ssb) if ssb.size else (), ssb, sbb)


def raster_compare_line(registers: bytes) -> int:
    return (registers[REG_CONTROL1] & CONTROL1_RST8) << 1 | registers[REG_RASTER]


def raster_irq_time(video: Video, registers: bytes) -> int | None:
    """Frame time at which the raster compare sets $D019 bit 0, or None if the line never comes."""
    line = raster_compare_line(registers)
    if line >= video.lines:
        return None
    return line * video.cycles_per_line + (RASTER_IRQ_LINE0_DELAY if line == 0 else 0)


def irq_register(latched: int, enabled: int) -> int:
    """$D019 as read: latched sources, unused bits 1, bit 7 while a latched source is enabled."""
    value = (latched & IRQ_SOURCES) | UNUSED_BITS[REG_IRQ_LATCH]
    return value | (IRQ_ANY if latched & enabled & IRQ_SOURCES else 0)


@dataclass(frozen=True)
class LatchReport:
    """What a program reading the registers after N frames would see, plus what it cannot see."""

    d01e: int
    d01f: int
    d019: int
    first_d01e: tuple[int, int] | None  # (raster line, X) of the first overlap pixel in frame 1
    first_d01f: tuple[int, int] | None
    pairs: tuple[tuple[int, int], ...]
    frames: int
    collisions: FrameCollisions


def run_frames(state: VicState, frames: int = 1) -> LatchReport:
    """$D01E, $D01F and $D019 after `frames` frames of an unchanging state (nothing reads them).

    The state is the same every frame, so every frame sets the same bits; $D019's collision bits
    latch when their register first goes from zero to non-zero, the raster bit when the compare line
    is reached.
    """
    if frames < 1:
        raise ValueError("frames must be >= 1")
    events = frame_collisions(state)
    latched = (IRQ_SPRITE_SPRITE if events.d01e else 0) | (IRQ_SPRITE_BACKGROUND if events.d01f else 0)
    if raster_irq_time(state.video, state.registers) is not None:
        latched |= IRQ_RASTER
    return LatchReport(events.d01e, events.d01f, irq_register(latched, state.registers[REG_IRQ_ENABLE]),
                       events.first_ss, events.first_sb, events.pairs, frames, events)
