"""The VIC-II collision model: one frame of a register state -> $D01E/$D01F events with numpy masks.

Rules [Bauer 3.8.1-3.8.2, PRG p.145]:
- Sprite n's DMA starts on the raster line whose low 8 bits equal its Y (the compare is 8-bit, so a
  small Y matches again on lines 256+ where they exist) and fetches one row per line (each row on
  two lines with Y expansion). A match while the sprite's DMA is still running is ignored. The state
  is taken as steady (it held in the previous frame too), so a sprite that runs past the last line
  continues at the top of the frame.
- Each row is shown from the sprite's X on (pixel i at X + i; X + 2i, X + 2i + 1 expanded), by the
  sprite sequencer, which steps through 8 positions per cycle (line_slots): a row fetched in line L
  is shown on line L + 1, or on line L when X comes after the sprite's own fetch in the line. The
  sprite gap (constants.SPRITE_HALT_PIXEL): around its own fetch a sprite repeats its last pixel,
  then drops the rest of the row; a sprite whose X falls there never shows; the last row of a
  sprite whose X comes after the display check (X $164 on the 6569) is never shown. X is 9 bits;
  X coordinates wrap after the last one that exists ($1F7 on the 6569, so a sprite at $1F8-$1FF
  never shows; $1FF on the 6567R8, whose sequencer draws X $180-$187 twice, and on the 6567R56A,
  whose 64 cycles draw each X once). Hires `1` and multicolor `01`, `10`, `11` are opaque.
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

from retro.chips.vic.beam import beam_key
from retro.chips.vic.constants import (
    COLLISION_LATCH_DELAY,
    CONTROL1_RST8,
    IRQ_ANY,
    IRQ_RASTER,
    IRQ_SOURCES,
    IRQ_SPRITE_BACKGROUND,
    IRQ_SPRITE_SPRITE,
    PIXELS_PER_CYCLE,
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
    SPRITE_DMA_CYCLES,
    SPRITE_DROP_PIXEL,
    SPRITE_HALT_PIXEL,
    SPRITE_HEIGHT,
    SPRITE_LOAD_PIXEL,
    SPRITE_PENDING_PIXEL,
    SPRITE_RESUME_PIXEL,
    UNUSED_BITS,
    X_BITS_MASK,
    Y_COMPARE_MASK,
    Video,
)
from retro.chips.vic.graphics import VicMemory, foreground_points
from retro.chips.vic.sprite_bits import opaque_mask, row_sources, switched_mask
from retro.chips.vic.sprite_registers import sprite_x

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
    # what the sprite data and memory were fetched from (retro.chips.vic.fetch); b"": given directly
    view_key: bytes = b""
    # False: the frame has no Bad Line (DEN clear in line $30), so an opened border shows the idle
    # byte in every window line (graphics.line_slots); the device sets it from what it sampled
    bad_lines: bool = True
    # per sprite: the (pixel from the row's start, expand_x, multicolor) switches of a $D01D/$D01C
    # write within the row being shown (sprite_bits.row_sources); () or all empty: none
    sprite_switches: tuple[tuple[tuple[int, bool, bool], ...], ...] = ()

    def __post_init__(self) -> None:
        if len(self.registers) != REGISTER_COUNT or len(self.sprite_data) != SPRITE_COUNT:
            raise ValueError("VicState needs 47 registers and 8 sprites")

    def with_registers(self, registers: bytes, bad_lines: bool = True, sprite_switches: tuple = ()) -> "VicState":
        return replace(self, registers=bytes(registers), bad_lines=bad_lines, sprite_switches=sprite_switches)

    def collision_key(self) -> bytes:
        switched = repr(self.sprite_switches).encode() if any(self.sprite_switches) else b""
        return bytes(self.registers[r] for r in COLLISION_REGISTERS) + bytes([self.bad_lines]) + switched + self.view_key

    def sprite_x(self, n: int) -> int:
        return sprite_x(self.registers, n)

    def sprite_y(self, n: int) -> int:
        return self.registers[REG_SPRITE_Y0 + 2 * n]

    def sprite_flag(self, register: int, n: int) -> bool:
        return bool((self.registers[register] >> n) & 1)


@dataclass(frozen=True)
class Placement:
    """Where one sprite's opaque pixels fall in the frame: pixel k at (lines[k], xs[k]) shows
    column cols[k] of the sprite's row rows[k] (columns of the X-expanded row; a pixel repeated by
    the sprite gap shows the column before the gap again). Lines and X as everywhere in the model:
    the raster line in which Bauer's X counter shows that X."""

    sprite: int
    x: int  # the sprite's X register
    lines: np.ndarray
    xs: np.ndarray
    rows: np.ndarray
    cols: np.ndarray


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

    def pair_pixels(self, a: int, b: int) -> tuple[np.ndarray, np.ndarray]:
        """(lines, xs) where sprites a and b are both opaque, each (line, X) once, in beam order (a
        place where three sprites meet is one place of each of their pairs)."""
        lines, xs = self.ss_pixels
        if not lines.size:
            return lines, xs
        places = lines * self.video.x_positions + xs
        unique, inverse = np.unique(places, return_inverse=True)
        together = np.zeros(unique.size, np.uint8)
        np.bitwise_or.at(together, inverse, self.ss_pixel_bits)
        both = (together >> a & 1).astype(bool) & (together >> b & 1).astype(bool)
        return unique[both] // self.video.x_positions, unique[both] % self.video.x_positions

    def background_pixels(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(lines, xs) where sprite n's opaque pixels meet foreground graphics."""
        lines, xs = self.sb_pixels
        mine = self.sb_pixel_bits == (1 << n)
        return lines[mine], xs[mine]

    @property
    def d01e(self) -> int:
        return int(np.bitwise_or.reduce(self.ss_bits)) if self.ss_bits.size else 0

    @property
    def d01f(self) -> int:
        return int(np.bitwise_or.reduce(self.sb_bits)) if self.sb_bits.size else 0


@lru_cache(maxsize=2048)
def sprite_rows(video: Video, y: int, expand_y: bool) -> np.ndarray:
    """Row fetched in the line before each raster line (-1: none) in the steady state, for Y = y:
    the row shown on that line by a sprite that starts before its own fetch (shown_rows).

    DMA starts at a line whose low 8 bits equal y, unless the sprite's DMA is still on from an
    earlier start [Bauer 3.8.1]; it runs 21 rows (42 lines expanded) and may cross into the next
    frame. Simulated over a few frames; the last one is the steady state.
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
def _sprite_shape(data: bytes, multicolor: bool, expand_x: bool, switches: tuple = ()) -> np.ndarray:
    if switches:  # a $D01D/$D01C write within the row: as the sequencer goes on drawing it
        return switched_mask(data, row_sources(expand_x, multicolor, switches))
    mask = opaque_mask(data, multicolor)
    return np.repeat(mask, 2, axis=1) if expand_x else mask


@dataclass(frozen=True, eq=False)
class SequencerSlots:
    """The positions the sprite sequencer steps through in a raster line ("slots", 8 per cycle from
    the first pixel of cycle 1) and the X coordinate compared and drawn at each."""

    x_at: np.ndarray  # X at each slot of a line
    slots_of_x: tuple[tuple[int, ...], ...]  # per 9-bit X: the slots that draw it (none: X does not exist)
    x_at_twice: np.ndarray  # x_at for two lines (a row runs into the next line)


@lru_cache(maxsize=None)
def sequencer_slots(video: Video) -> SequencerSlots:
    """Cycle 1 starts at X first_x - COLLISION_LATCH_DELAY; each slot draws the next X, wrapping after
    the last X that exists; on the 6567R8 cycle 63 draws the X of cycle 62 again."""
    slot = np.arange(video.line_slots)
    repeat = np.zeros(video.line_slots, dtype=np.int64)
    if video.repeated_x_cycle:
        repeat[(video.repeated_x_cycle - 1) * PIXELS_PER_CYCLE:] = PIXELS_PER_CYCLE
    x_at = (video.first_x - COLLISION_LATCH_DELAY + slot - repeat) % video.x_positions
    x_at_twice = np.concatenate([x_at, x_at])
    x_at.flags.writeable = x_at_twice.flags.writeable = False
    slots_of_x = tuple(tuple(np.flatnonzero(x_at == x).tolist()) for x in range(X_BITS_MASK + 1))
    return SequencerSlots(x_at, slots_of_x, x_at_twice)


@dataclass(frozen=True)
class SpriteGap:
    """Sprite n's sequencer events, in slots from the start of the line where its fetch begins
    (past line_slots: in the next line); see constants.SPRITE_HALT_PIXEL."""

    halt: int  # halted from here (repeats its last pixel) ...
    drop: int  # ... the rest of the row dropped from here ...
    load: int  # ... the row just fetched loaded here ...
    resume: int  # ... and a sprite may start again from here
    pending: int  # the sequencer's copy of the display flags is taken here (all sprites)


@lru_cache(maxsize=None)
def sprite_gap(video: Video, n: int) -> SpriteGap:
    pointer = (video.sprite0_fetch_cycle - 1 + SPRITE_DMA_CYCLES * n) * PIXELS_PER_CYCLE
    after = pointer + PIXELS_PER_CYCLE  # the cycle of its other s-accesses
    return SpriteGap(halt=pointer + SPRITE_HALT_PIXEL, drop=after + SPRITE_DROP_PIXEL, load=after + SPRITE_LOAD_PIXEL,
                     resume=after + SPRITE_RESUME_PIXEL,
                     pending=(video.display_check_cycle - 1) * PIXELS_PER_CYCLE + SPRITE_PENDING_PIXEL)


def start_slot(video: Video, n: int, x: int) -> int | None:
    """The slot of a line at which sprite n at X = x starts each row, or None: X does not exist, or
    every slot drawing it falls while the sprite is halted (the sprite never shows)."""
    gap = sprite_gap(video, n)
    for slot in sequencer_slots(video).slots_of_x[x & X_BITS_MASK]:
        if (slot - gap.halt) % video.line_slots >= gap.resume - gap.halt:
            return slot
    return None


def load_period(video: Video, n: int, slot: int) -> tuple[int, int]:
    """[first, end) slots (counted like `slot`, from any frame's cycle 1) from sprite n's last row
    load at or before `slot` to its next one. Its shift register holds that row there and starts it
    at most once: a start while it shifts is ignored, one after it ran empty shows nothing [VICE-src
    viciisc/vicii-draw-cycle.c: trigger_sprites, draw_sprites, update_sprite_data]."""
    first = slot - (slot - sprite_gap(video, n).load) % video.line_slots
    return first, first + video.line_slots


def start_in_period(video: Video, n: int, x: int, first: int) -> int | None:
    """The slot at which sprite n at X = x starts in the load period that begins at slot `first`,
    or None when that X never starts it (see start_slot)."""
    slot = start_slot(video, n, x)
    return None if slot is None else first + (slot - first) % video.line_slots


def shown_rows(video: Video, n: int, y: int, expand_y: bool, slot: int) -> np.ndarray:
    """Row of sprite n started at `slot` in each raster line (counted in slots from cycle 1), -1: none.

    The row shown is the last one loaded before the slot: fetched in the line before, or in the same
    line when the slot comes after the sprite's own load (two lines before for sprites whose fetch
    runs into the next line). The sequencer starts it only if its copy of the display flag, taken in
    this line's display check or the one before, is set; the flag is on in the lines the sprite
    fetches. A start with the flag set but no row fetched yet shows what the VIC read with DMA off
    (the last CPU bus byte and the idle byte): not modelled, nothing is shown.
    """
    gap = sprite_gap(video, n)
    return _rows_lagged(video, y, expand_y, -((slot - gap.load) // video.line_slots), 0 if slot >= gap.pending else 1)


@lru_cache(maxsize=2048)
def _rows_lagged(video: Video, y: int, expand_y: bool, data_lag: int, flag_lag: int) -> np.ndarray:
    """Per line: the row fetched data_lag lines before, if the display flag was on flag_lag lines before."""
    fetched = np.roll(sprite_rows(video, y, expand_y), -1)  # the row fetched in each line
    rows = np.where(np.roll(fetched >= 0, flag_lag), np.roll(fetched, data_lag), -1)
    rows.flags.writeable = False
    return rows


@dataclass(frozen=True)
class _Columns:
    """The columns of the (expanded) row drawn at each slot from a start slot on: the whole row,
    unless the sprite's halt comes before its end; then the columns up to the halt, the last of them
    repeated until the drop, and nothing after. Per column also: its slot counted from the start of
    the line, its line counted from the row's line in the model's line numbering, and its X."""

    columns: np.ndarray
    whole: bool  # columns is 0 .. width-1
    slots: np.ndarray
    line_shift: np.ndarray
    xs: np.ndarray


@lru_cache(maxsize=4096)
def _columns(video: Video, n: int, slot: int, width: int) -> _Columns:
    gap = sprite_gap(video, n)
    to_halt = (gap.halt - slot) % video.line_slots
    whole = to_halt > width
    if whole:
        columns = np.arange(width)
    else:
        columns = np.concatenate([np.arange(to_halt), np.full(gap.drop - gap.halt, to_halt - 1)])
    slots = np.arange(slot, slot + columns.size)
    # The model's raster line of a pixel is the one in which Bauer's counter shows its X, which runs
    # COLLISION_LATCH_DELAY ahead of the sequencer (see sequencer_slots): the first slots of a line
    # belong to the line before, and a row running past the line's last slot to the next line.
    line_shift = np.zeros(columns.size, dtype=np.int64)
    line_shift[:max(0, COLLISION_LATCH_DELAY - slot)] = -1
    line_shift[max(0, video.line_slots + COLLISION_LATCH_DELAY - slot):] = 1
    made = _Columns(columns, whole, slots, line_shift, sequencer_slots(video).x_at_twice[slots])
    for array in (columns, slots, line_shift, made.xs):
        array.flags.writeable = False  # shared through the cache
    return made


def _pixels(video: Video, n: int, x: int, y: int, expand_y: bool, data: bytes, multicolor: bool, expand_x: bool,
            switches: tuple = ()):
    """(lines with a row, their rows, the columns, line index and column index of each opaque pixel)."""
    slot = start_slot(video, n, x)
    if slot is None:
        return None
    shape = _sprite_shape(data, multicolor, expand_x, switches)
    rows = shown_rows(video, n, y, expand_y, slot)
    row = _columns(video, n, slot, shape.shape[1])
    lines = np.flatnonzero(rows >= 0)
    line_rows = rows[lines]
    i, k = np.nonzero(shape[line_rows] if row.whole else shape[line_rows][:, row.columns])
    return lines, line_rows, row, i, k


@dataclass(frozen=True)
class _Placed:
    """One sprite's opaque pixels: frame slot (lines x line_slots), raster line and X."""

    places: np.ndarray
    lines: np.ndarray
    xs: np.ndarray


# Keyed on everything a sprite's pixels depend on, so a device or loop that keeps a sprite still
# (or returns it to a place) pays for its placement once.
@lru_cache(maxsize=4096)
def _placed(video: Video, n: int, x: int, y: int, expand_y: bool, data: bytes, multicolor: bool,
            expand_x: bool, switches: tuple = ()) -> _Placed | None:
    found = _pixels(video, n, x, y, expand_y, data, multicolor, expand_x, switches)
    if found is None:
        return None
    lines, _, row, i, k = found
    base = lines[i]
    places = base * video.line_slots
    places += row.slots[k]
    pixel_lines = base + row.line_shift[k]
    if lines.size and (lines[0] == 0 or lines[-1] == video.lines - 1):  # the frame's edge: wrap
        places %= video.lines * video.line_slots
        pixel_lines %= video.lines
    placed = _Placed(places, pixel_lines, row.xs[k])
    for array in vars(placed).values():
        array.flags.writeable = False  # shared through the cache: nobody may change them
    return placed


def _sprite_key(state: VicState, n: int) -> tuple | None:
    """What sprite n's pixels depend on (the arguments of _placed), or None when it is disabled."""
    if not state.sprite_flag(REG_SPRITE_ENABLE, n):
        return None
    return (state.video, n, state.sprite_x(n), state.sprite_y(n), state.sprite_flag(REG_SPRITE_EXPAND_Y, n),
            bytes(state.sprite_data[n][:SPRITE_BYTES]), state.sprite_flag(REG_SPRITE_MULTICOLOR, n),
            state.sprite_flag(REG_SPRITE_EXPAND_X, n), state.sprite_switches[n] if state.sprite_switches else ())


def _placed_sprite(state: VicState, n: int) -> _Placed | None:
    key = _sprite_key(state, n)
    return None if key is None else _placed(*key)


def placement(state: VicState, n: int) -> Placement | None:
    """Sprite n's opaque pixels in the frame, or None when it shows nowhere (disabled, X in the
    6569's gap $1F8-$1FF, or X falling while the sprite is halted for its own fetch).

    lines and xs are shared with a cache and read-only."""
    key = _sprite_key(state, n)
    placed = None if key is None else _placed(*key)
    if placed is None:
        return None
    _, line_rows, row, i, k = _pixels(*key)
    return Placement(n, state.sprite_x(n), placed.lines, placed.xs, line_rows[i], row.columns[k])


def _opaque_pixels(state: VicState) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(slots, lines, xs, sprite bit) of every opaque pixel of every shown sprite, by sprite then
    row-major. That order is the order in which the pixel lists of FrameCollisions are reported.
    """
    shown = [(n, placed) for n in range(SPRITE_COUNT)
             if (placed := _placed_sprite(state, n)) is not None and placed.places.size]
    if not shown:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty, np.zeros(0, np.uint8)
    places = np.concatenate([placed.places for _, placed in shown]).astype(np.int64, copy=False)
    lines = np.concatenate([placed.lines for _, placed in shown]).astype(np.int64, copy=False)
    xs = np.concatenate([placed.xs for _, placed in shown]).astype(np.int64, copy=False)
    bits = np.repeat(np.array([1 << n for n, _ in shown], np.uint8), [placed.places.size for _, placed in shown])
    return places, lines, xs, bits


def _lower_sprites_under(video: Video, places: np.ndarray, bits: np.ndarray) -> np.ndarray:
    """For each opaque pixel, the OR of the bits of lower-numbered sprites opaque at the same place
    (the same sequencer slot of the frame: on the 6567R8 the two slots drawing one X are two places).

    A sprite has at most one pixel per place and each bit is one sprite, so OR-ing all bits per
    place and keeping those below the pixel's own bit gives what a canvas drawn sprite 0, 1, ...
    would hold when the pixel's sprite is drawn. For the same reason the OR is a sum of distinct
    powers of two, and np.add.at is about twice as fast as np.bitwise_or.at.
    """
    canvas = np.zeros(video.lines * video.line_slots, np.uint8)
    np.add.at(canvas, places, bits)
    return canvas[places] & (bits - 1)


def _pairs(bit_sets: np.ndarray) -> tuple[tuple[int, int], ...]:
    found = set()
    for value in np.flatnonzero(np.bincount(bit_sets, minlength=1)).tolist():  # distinct sets, no sort needed
        members = [n for n in range(SPRITE_COUNT) if value >> n & 1]
        found.update((a, b) for i, a in enumerate(members) for b in members[i + 1:])
    return tuple(sorted(found))


def _events(video: Video, lines: np.ndarray, xs: np.ndarray, bits: np.ndarray, places: np.ndarray):
    """(latch times, the sprite bits latched at each, (line, X) of the first pixel in beam order).
    A pixel latches in the cycle of its sequencer slot (`places`), which on the 6567R8 also counts
    the cycle that draws X $180-$187 a second time."""
    if lines.size == 0:
        empty = np.zeros(0, np.int64)
        return empty, np.zeros(0, np.uint8), None
    times = places // PIXELS_PER_CYCLE % video.frame_cycles
    order = np.argsort(times, kind="stable")  # the pixels come nearly in time order: a cheap sort
    times, bits = times[order], bits[order]
    start = np.flatnonzero(np.concatenate(([True], times[1:] != times[:-1])))  # first of each time
    merged = np.bitwise_or.reduceat(bits, start).astype(np.uint8)
    first = int(np.argmin(beam_key(video, lines, xs)))
    return times[start], merged, (int(lines[first]), int(xs[first]))


def frame_collisions(state: VicState) -> FrameCollisions:
    """All sprite-sprite and sprite-background overlap events of one frame of state."""
    video = state.video
    places, lines, xs, bits = _opaque_pixels(state)
    under = _lower_sprites_under(video, places, bits)
    ss = under != 0
    ssl, ssx, ssb = lines[ss], xs[ss], under[ss] | bits[ss]
    sb = foreground_points(video, state.memory, state.registers[REG_CONTROL1], state.registers[REG_CONTROL2],
                           lines, xs, state.bad_lines)
    sbl, sbx, sbb = lines[sb], xs[sb], bits[sb]
    ss_times, ss_merged, first_ss = _events(video, ssl, ssx, ssb, places[ss])
    sb_times, sb_merged, first_sb = _events(video, sbl, sbx, sbb, places[sb])
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
