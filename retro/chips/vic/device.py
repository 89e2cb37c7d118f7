"""The VIC-II as a bus device at $D000-$D3FF, driven lazily by the CPU's cycle clock.

Nothing runs per cycle. When the CPU touches a register at cycle m, the device first catches up:
it applies every collision event drawn since its last access (from the frame schedule of the
register state that held meanwhile, model.frame_collisions, cached per state), then serves the
access. A write to a register that changes what collides switches to the new state's schedule from
the next cycle on, so programs can move sprites between frames or between raster bands.

Register behaviour [Bauer 3.2, 3.8.2, 3.12]:
- the 47 registers repeat every 64 bytes; $D02F-$D03F read $FF; unused bits read 1;
- $D011 bit 7 and $D012 read the current raster line; writes set the raster compare line;
- $D01E/$D01F accumulate until read; a read (of any mirror) returns them and clears them; writes
  are ignored;
- $D019 bit 2 / bit 1 latch when $D01E / $D01F goes from zero to non-zero, bit 0 when the raster
  compare line begins; bit 7 reads 1 while a latched bit is enabled in $D01A; writing 1s
  acknowledges; reading $D01E/$D01F does not touch $D019.
Timing model: retro.chips.vic.beam.

CPU lines (a retro.cpu.bus.CpuLines): BA from the Bad Line and sprite DMA schedule of the current
register state (retro.chips.vic.dma), and the IRQ output, low while a bit latched in $D019 is
enabled in $D01A [Bauer 3.12]. `irq_next` is the machine cycle at which the next enabled source can
latch (the raster compare, or the first collision while its register is zero), so the CPU asks the
device only when a poll reaches it.
"""

from __future__ import annotations

import numpy as np

from retro.chips.vic.beam import position
from retro.chips.vic.constants import (
    BA_LEAD,
    CONTROL1_DEN,
    CONTROL1_RSEL,
    CONTROL1_RST8,
    EXPAND_X_SWITCH_PIXEL,
    GRAPHICS_FIRST_LINE,
    IRQ_RASTER,
    IRQ_SOURCES,
    IRQ_SPRITE_BACKGROUND,
    IRQ_SPRITE_SPRITE,
    MIRROR_SIZE,
    MULTICOLOR_SWITCH_PIXEL,
    PIXELS_PER_CYCLE,
    RASTER_IRQ_LINE0_DELAY,
    READ_ONLY_LATCHES,
    REG_CONTROL1,
    REG_IRQ_ENABLE,
    REG_IRQ_LATCH,
    REG_LIGHTPEN_X,
    REG_LIGHTPEN_Y,
    REG_RASTER,
    REG_SPRITE_BACKGROUND,
    REG_SPRITE_ENABLE,
    REG_SPRITE_EXPAND_X,
    REG_SPRITE_EXPAND_Y,
    REG_SPRITE_MULTICOLOR,
    REG_SPRITE_SPRITE,
    REG_SPRITE_X0,
    REG_SPRITE_X_MSB,
    REG_SPRITE_Y0,
    REGISTER_COUNT,
    SPRITE_COUNT,
    SPRITE_DMA_CHECK_CYCLES,
    UNUSED_BITS,
    UNUSED_READ,
    WINDOW_LINES,
    VIC_BASE,
    Y_COMPARE_MASK,
)
from retro.chips.vic.dma import DMA_REGISTERS, bus_schedule
from retro.chips.vic.model import (
    COLLISION_REGISTERS,
    FrameCollisions,
    VicState,
    frame_collisions,
    irq_register,
    load_period,
    raster_compare_line,
    raster_irq_time,
    sprite_rows,
    start_in_period,
)
from retro.chips.vic.sprite_bits import row_sources
from retro.chips.vic.sprite_registers import set_sprite_x, sprite_x
from retro.cpu.bus import NEVER

SCHEDULE_CACHE_SIZE = 256
_COLLISION_SET = frozenset(COLLISION_REGISTERS)
_READ_ONLY = frozenset({REG_SPRITE_SPRITE, REG_SPRITE_BACKGROUND, REG_LIGHTPEN_X, REG_LIGHTPEN_Y})
_DMA_SET = frozenset(DMA_REGISTERS)
_SAMPLED_SET = frozenset({REG_CONTROL1, REG_SPRITE_ENABLE})
_X_SET = frozenset(range(REG_SPRITE_X0, REG_SPRITE_X_MSB, 2)) | {REG_SPRITE_X_MSB}
_SWITCH_PIXEL = {REG_SPRITE_EXPAND_X: EXPAND_X_SWITCH_PIXEL, REG_SPRITE_MULTICOLOR: MULTICOLOR_SWITCH_PIXEL}
# What a sample point samples (see VicDevice._latch_points): sprite n's first and second DMA check
# and its display check are n + SPRITE_COUNT * (LATCH_DMA_FIRST, LATCH_DMA_SECOND, LATCH_SPRITE_DISPLAY)
LATCH_DMA_FIRST, LATCH_DMA_SECOND, LATCH_SPRITE_DISPLAY = range(3)
LATCH_BAD_LINES = 3 * SPRITE_COUNT
LATCH_BORDER = 3 * SPRITE_COUNT + 1


def _next_event(times: np.ndarray, after: int, frame_cycles: int) -> int | None:
    """Device time of the first event at or after `after`, events repeating every frame."""
    if times.size == 0:
        return None
    within = after % frame_cycles
    i = int(np.searchsorted(times, within))
    if i < times.size:
        return after + int(times[i]) - within
    return after + frame_cycles - within + int(times[0])


def _bits_between(times: np.ndarray, bits: np.ndarray, lo: int, hi: int, frame_cycles: int) -> int:
    """OR of the event bits with device time in [lo, hi), events repeating every frame."""
    if hi <= lo or times.size == 0:
        return 0
    if hi - lo >= frame_cycles:
        return int(np.bitwise_or.reduce(bits))
    a = lo % frame_cycles
    b = a + (hi - lo)
    windows = [(a, b)] if b <= frame_cycles else [(a, frame_cycles), (0, b - frame_cycles)]
    found = 0
    for start, end in windows:
        i, j = np.searchsorted(times, [start, end])
        if j > i:
            found |= int(np.bitwise_or.reduce(bits[i:j]))
    return found


def _time_between(t: int | None, lo: int, hi: int, frame_cycles: int) -> bool:
    """Whether a once-per-frame event at frame time t happens in device time [lo, hi)."""
    if t is None or hi <= lo:
        return False
    if hi - lo >= frame_cycles:
        return True
    return (t - lo) % frame_cycles < hi - lo


class VicDevice:
    """A VIC-II whose frame starts (line 0, cycle 1) at machine cycle `start_cycle`."""

    chip_name = "VIC-II"
    drives_cpu_lines = True
    nmi_next = NEVER  # the VIC-II has no NMI output

    @classmethod
    def at_beam(cls, state: VicState, cycle: int, line: int = 0, line_cycle: int = 1, *,
                drawn: bool = False, fetcher=None) -> "VicDevice":
        """A device whose beam is at `line`, cycle `line_cycle` (1-based) at machine cycle `cycle`.

        With `drawn`, the frame so far has been drawn with this state since its line 0, cycle 1: its
        collisions are in $D01E/$D01F (unread since) and its raster compare and collision events in
        $D019 (unacknowledged), as the machine would have them. Without it nothing is taken to have
        happened earlier in that frame (no raster compare, no collision). `fetcher`: a
        retro.chips.vic.fetch.VicFetcher when the chip reads its memory (else `state` holds it).
        """
        video = state.video
        if not 0 <= line < video.lines or not 1 <= line_cycle <= video.cycles_per_line:
            raise ValueError(f"no line {line}, cycle {line_cycle} on the {video.chip}")
        offset = line * video.cycles_per_line + line_cycle - 1
        device = cls(state, start_cycle=cycle - offset, fetcher=fetcher)
        if drawn:
            device._advance(offset)
        else:
            device.synced = offset
            device._refresh_irq_next()
        return device

    def restart(self, cycle: int, line: int, line_cycle: int = 1, *, drawn: bool = False) -> None:
        """Back to the scene's registers with the beam at `line`, `line_cycle` at machine cycle `cycle`,
        as `at_beam` makes it (for runs of many calls that each start at the same raster position).
        The bus keeps this object, so its state is replaced in place; the collision cache is kept."""
        schedules = self._schedules
        fresh = type(self).at_beam(self.state, cycle, line, line_cycle, drawn=drawn, fetcher=self.fetcher)
        self.__dict__.update(fresh.__dict__)
        self._schedules.update(schedules)

    def __init__(self, state: VicState, start_cycle: int = 0, fetcher=None) -> None:
        self.fetcher = fetcher
        if fetcher is not None:
            state = fetcher.state_for(state, state.registers)
        self.state = state
        self.video = state.video
        self.start_cycle = start_cycle
        self.registers = bytearray(state.registers)
        # What the chip acts on where it samples a register only at certain cycles (see _latch):
        # each sprite's $D015 bit when its DMA starts, DEN in line $30 and in the first window line.
        self.sprite_enable = self.registers[REG_SPRITE_ENABLE]  # the DMA started with $D015 set
        self.sprite_display = self.registers[REG_SPRITE_ENABLE]  # ... and shown ($D015 still set at its display check)
        self.bad_lines_allowed = self.display_opened = bool(self.registers[REG_CONTROL1] & CONTROL1_DEN)
        self._latching = False  # some of those differ from the registers as written
        self._sampled_until = 0  # device time up to which (exclusive) the samples have been taken
        self._next_latch_at = NEVER  # device time of the next sample that can change something
        self._raster_match_at: int | None = None  # a compare matched by a write latches here
        # sprite n -> (device time it ends, the X its row started at or None: no row) while an X
        # write does not move the row of the current load period (see _hold_started_rows)
        self._rows_held: dict[int, tuple[int, int | None]] = {}
        # sprite n -> (device time it ends, expand_x and multicolor at the row's start, the switches
        # since) while a $D01D/$D01C write changes the row being shown (see _switch_rows_in_progress)
        self._shapes_held: dict[int, tuple[int, bool, bool, tuple]] = {}
        self.sprite_sprite = 0  # $D01E as accumulated since the last read
        self.sprite_background = 0  # $D01F
        self.irq_latch = 0  # $D019 bits 0-3
        self.synced = 0  # device time up to which (exclusive) events have been applied
        self._schedules: dict[bytes, FrameCollisions] = {}
        self._schedule = self._schedule_for(state)
        self._bus = bus_schedule(self.video, self.registers)
        self.irq_next = NEVER
        self._refresh_irq_next()

    # ---- catching up -------------------------------------------------------------------------

    def _schedule_for(self, state: VicState) -> FrameCollisions:
        key = state.collision_key()
        schedule = self._schedules.get(key)
        if schedule is None:
            if len(self._schedules) >= SCHEDULE_CACHE_SIZE:
                self._schedules.clear()
            schedule = self._schedules[key] = frame_collisions(state)
        return schedule

    def _advance(self, until: int) -> None:
        """Apply everything the beam draws in device time [synced, until)."""
        while self._latching:
            point = self._next_latch_point(max(self.synced, self._sampled_until), until)
            if point is None:
                break
            self._apply(point)
            self._latch(point)
            self._sampled_until = point + 1
        self._apply(until)

    # ---- registers the chip samples at certain cycles ------------------------------------------
    # [Bauer 3.5, 3.8.1, 3.9; VICE-src vicii-cycle.c: check_sprite_dma, check_vborder_top, allow_bad_lines]
    # - sprite n's DMA starts where Y matches the line in the first or second DMA check cycle
    #   (SPRITE_DMA_CHECK_CYCLES from sprite0_fetch_cycle - BA_LEAD) only if its $D015 bit is set
    #   then; once on, it runs its 21 rows (42 expanded) whatever $D015 says, and a sprite enabled
    #   later shows from its next start on; it is shown only if $D015 is still set in the display
    #   check of that line (display_check_cycle, 58 on the 6569: VICE's check_sprite_display tests
    #   MxE there; Bauer 3.8.1 does not say), else it fetches and steals cycles unseen;
    # - Bad Lines exist in a frame only if DEN was set in some cycle of line $30;
    # - the vertical border opens in the first line of the window (51, or 55 with RSEL = 0) only
    #   if DEN is set in some cycle of that line, so graphics collide only then.
    # The model takes each sampled bit as holding all frame (sprites from their start, Bad Lines
    # from line $30, the display from the window's first line).

    def _latch_points(self) -> list[tuple[int, int]]:
        """(frame time, what is sampled there) in frame order (the LATCH_ codes above)."""
        video = self.video
        cpl = video.cycles_per_line
        first_check = video.sprite0_fetch_cycle - BA_LEAD - 1  # 0-based cycle in the line
        display_check = video.display_check_cycle - 1
        points = [(GRAPHICS_FIRST_LINE * cpl, LATCH_BAD_LINES),
                  (WINDOW_LINES[1 if self.registers[REG_CONTROL1] & CONTROL1_RSEL else 0][0] * cpl, LATCH_BORDER)]
        written = self.registers[REG_SPRITE_ENABLE]
        for n in range(SPRITE_COUNT):
            if ((written ^ self.sprite_enable) | (written ^ self.sprite_display)) >> n & 1:
                y = self.registers[REG_SPRITE_Y0 + 2 * n]
                expand = bool(self.registers[REG_SPRITE_EXPAND_Y] >> n & 1)
                rows = sprite_rows(video, y, expand)
                for line in range(y, video.lines, Y_COMPARE_MASK + 1):
                    if rows[(line + 1) % video.lines] == 0:  # the DMA starts at this match
                        for k in range(SPRITE_DMA_CHECK_CYCLES):
                            points.append((line * cpl + first_check + k, n + (LATCH_DMA_FIRST + k) * SPRITE_COUNT))
                        points.append((line * cpl + display_check, n + LATCH_SPRITE_DISPLAY * SPRITE_COUNT))
        return sorted(points)

    def _next_latch_point(self, lo: int, hi: int) -> int | None:
        """The first device time in [lo, hi) where a sampled bit can change."""
        frame_cycles = self.video.frame_cycles
        found = [lo + (p - lo) % frame_cycles for p, _ in self._latch_points()]
        found += [max(lo, until) for until, _ in self._rows_held.values()]
        found += [max(lo, held[0]) for held in self._shapes_held.values()]
        first = min(found, default=None)
        return first if first is not None and first < hi else None

    def _latch(self, t: int) -> None:
        """The chip samples the registers as written at device time t."""
        self._rows_held = {n: held for n, held in self._rows_held.items() if held[0] > t}
        self._shapes_held = {n: held for n, held in self._shapes_held.items() if held[0] > t}
        within = t % self.video.frame_cycles
        den = bool(self.registers[REG_CONTROL1] & CONTROL1_DEN)
        for point, what in self._latch_points():
            if point != within:
                continue
            if what == LATCH_BAD_LINES:
                self.bad_lines_allowed = den
            elif what == LATCH_BORDER:
                self.display_opened = den
            else:
                kind, n = divmod(what, SPRITE_COUNT)
                bit = self.registers[REG_SPRITE_ENABLE] & (1 << n)
                if kind == LATCH_DMA_FIRST:
                    self.sprite_enable = self.sprite_enable & ~(1 << n) | bit
                elif kind == LATCH_DMA_SECOND:
                    self.sprite_enable |= bit
                else:
                    self.sprite_display = self.sprite_display & ~(1 << n) | (bit & self.sprite_enable)
        self._use_sampled()

    def _sample_within_line(self, t: int) -> None:
        """A DEN write in line $30 or in the window's first line counts for that line (any cycle)."""
        if not self.registers[REG_CONTROL1] & CONTROL1_DEN:
            return
        _, line, _ = position(self.video, t)
        if line == GRAPHICS_FIRST_LINE:
            self.bad_lines_allowed = True
        if line == WINDOW_LINES[1 if self.registers[REG_CONTROL1] & CONTROL1_RSEL else 0][0]:
            self.display_opened = True

    def _sampled_registers(self, den: bool, sprites: int) -> bytes:
        registers = bytearray(self.registers)
        registers[REG_SPRITE_ENABLE] = sprites
        registers[REG_CONTROL1] = registers[REG_CONTROL1] & ~CONTROL1_DEN | (CONTROL1_DEN if den else 0)
        return bytes(registers)

    # ---- a sprite X write within a line [VICE-src viciisc/vicii-draw-cycle.c: trigger_sprites,
    # draw_sprites, update_sprite_xpos; the VICE test program VICII/spritex/testsuite, PAL rows]
    # The sequencer compares X with the X written up to the cycle before (a write in cycle c counts
    # from cycle c + 1's first pixel) and starts the sprite's shift register where they match; that
    # register holds the row loaded at the sprite's fetch and starts at most once before the next
    # load (model.load_period). So in the load period of the write: a row already started keeps its
    # X to its end; one not started yet starts at the new X if the sequencer has not passed it, else
    # not at all; from the next load on the new X holds.

    def _hold_started_rows(self, register: int, value: int, first_new: int) -> None:
        """Hold the rows an X write at device time first_new - 1 does not move (see above)."""
        video = self.video
        written = bytearray(self.registers)
        written[register] = value
        slot = first_new * PIXELS_PER_CYCLE  # the first sequencer slot comparing the new X
        shown = self.state.registers[REG_SPRITE_ENABLE]  # ... where not hidden by a hold (below)
        for n, (_, x) in self._rows_held.items():
            shown |= (1 << n) if x is None else 0
        for n in range(SPRITE_COUNT):
            old_x, new_x = sprite_x(self.registers, n), sprite_x(written, n)
            if old_x == new_x or not shown >> n & 1:
                continue
            first, end = load_period(video, n, slot)
            # the period ends in the load's cycle: the cycle after it is all the next period's
            until = end // PIXELS_PER_CYCLE + 1
            held = self._rows_held.get(n)
            if held is not None and held[0] <= first_new:
                held = None  # from an earlier period
            if held is not None and held[1] is not None:
                continue  # started: the row keeps its X
            self._latching = True  # _use_sampled sets it from the holds
            if held is None:
                started = start_in_period(video, n, old_x, first)
                if started is not None and started < slot:
                    self._rows_held[n] = (until, old_x)
                    continue
            started = start_in_period(video, n, new_x, first)
            if started is not None and started < slot:
                self._rows_held[n] = (until, None)  # passed: no row until the next load
            else:
                self._rows_held.pop(n, None)

    # ---- a $D01D / $D01C write within a row [VICE-src viciisc/vicii-draw-cycle.c: draw_sprites8
    # takes the bits at pixel 6 / 7 of the write's cycle (constants.EXPAND_X_SWITCH_PIXEL), draw_sprites
    # goes on from where the shift register stands]. A row already started in the load period of the
    # write goes on with the new bit from that pixel (sprite_bits.row_sources), or, if it has ended,
    # stays as it was; a row not started yet is drawn with the new bit; from the next load on the new
    # bit holds. The device holds the row's start flags and the switches until that load, and
    # switches states from the write's own cycle (its pixels before the switch pixel are the same in
    # both). Not modelled: an X write and a $D01D/$D01C write to one sprite in one load period (the
    # X write's hold wins).

    def _switch_rows_in_progress(self, register: int, value: int, t: int) -> None:
        """Hold the rows a write of `value` to $D01D or $D01C at device time t changes (see above)."""
        video = self.video
        switch = t * PIXELS_PER_CYCLE + _SWITCH_PIXEL[register]  # the sequencer slot that takes it
        shown = self.state.registers[REG_SPRITE_ENABLE]
        for n in range(SPRITE_COUNT):
            if not (self.registers[register] ^ value) >> n & 1 or not shown >> n & 1 or n in self._rows_held:
                continue
            first, end = load_period(video, n, switch)
            started = start_in_period(video, n, sprite_x(self.registers, n), first)
            if started is None or started > switch:
                continue  # not started yet in this period: it starts with the new bit
            held = self._shapes_held.get(n)
            if held is not None and held[0] <= t + 1:
                held = None  # from an earlier period
            expand = bool(self.registers[REG_SPRITE_EXPAND_X] >> n & 1)
            multicolor = bool(self.registers[REG_SPRITE_MULTICOLOR] >> n & 1)
            base_expand, base_multicolor, switches = (expand, multicolor, ()) if held is None else held[1:]
            new_expand = bool(value >> n & 1) if register == REG_SPRITE_EXPAND_X else expand
            new_multicolor = bool(value >> n & 1) if register == REG_SPRITE_MULTICOLOR else multicolor
            offset = switch - started
            if offset < len(row_sources(base_expand, base_multicolor, switches)):
                switches = switches + ((offset, new_expand, new_multicolor),)  # in progress: it goes on switched
            self._latching = True  # _use_sampled sets it from the holds
            self._shapes_held[n] = (end // PIXELS_PER_CYCLE + 1, base_expand, base_multicolor, switches)

    def _with_held_shapes(self, registers: bytes) -> tuple[bytes, tuple]:
        """Collision registers with the held rows' start flags, and the switches per sprite."""
        if not self._shapes_held:
            return registers, ()
        held = bytearray(registers)
        switches = [()] * SPRITE_COUNT
        for n, (_, expand, multicolor, changes) in self._shapes_held.items():
            for register, bit in ((REG_SPRITE_EXPAND_X, expand), (REG_SPRITE_MULTICOLOR, multicolor)):
                held[register] = held[register] & ~(1 << n) | (bit << n)
            switches[n] = changes
        return bytes(held), tuple(switches)

    def _with_held_rows(self, registers: bytes) -> bytes:
        """Collision registers with the X (or no display) of the held rows."""
        if not self._rows_held:
            return registers
        held = bytearray(registers)
        for n, (_, x) in self._rows_held.items():
            if x is None:
                held[REG_SPRITE_ENABLE] &= ~(1 << n)
            else:
                set_sprite_x(held, n, x)
        return bytes(held)

    def _use_sampled(self) -> None:
        """Switch the collision and BA schedules to what the chip acts on now."""
        written_den = bool(self.registers[REG_CONTROL1] & CONTROL1_DEN)
        written = self.registers[REG_SPRITE_ENABLE]
        self._latching = (self.sprite_enable != written or self.sprite_display != written
                          or self.bad_lines_allowed != written_den or self.display_opened != written_den
                          or bool(self._rows_held) or bool(self._shapes_held))
        switches = ()
        if self._latching:
            # graphics where the border opened: from Bad Lines, or the idle byte in a frame without any
            collision_registers, switches = self._with_held_shapes(self._with_held_rows(
                self._sampled_registers(self.display_opened, self.sprite_enable & self.sprite_display)))
            bus_registers = self._sampled_registers(self.bad_lines_allowed, self.sprite_enable)
        else:
            collision_registers = bus_registers = self.registers
        self.state = self.state.with_registers(collision_registers, bad_lines=self.bad_lines_allowed,
                                               sprite_switches=switches)
        self._schedule = self._schedule_for(self.state)
        self._bus = bus_schedule(self.video, bus_registers)

    def _apply(self, until: int) -> None:
        """Apply the current schedule's events in device time [synced, until)."""
        lo = self.synced
        if until <= lo:
            return
        if self.fetcher is not None and self.fetcher.due(self.video, self.registers, lo, until):
            self._fetch()  # elsewhere what the VIC-II fetches changes nothing
        frame_cycles = self.video.frame_cycles
        events = self._schedule
        new_ss = _bits_between(events.ss_times, events.ss_bits, lo, until, frame_cycles)
        new_sb = _bits_between(events.sb_times, events.sb_bits, lo, until, frame_cycles)
        if new_ss and not self.sprite_sprite:
            self.irq_latch |= IRQ_SPRITE_SPRITE
        if new_sb and not self.sprite_background:
            self.irq_latch |= IRQ_SPRITE_BACKGROUND
        self.sprite_sprite |= new_ss
        self.sprite_background |= new_sb
        if _time_between(raster_irq_time(self.video, self.registers), lo, until, frame_cycles):
            self.irq_latch |= IRQ_RASTER
        if self._raster_match_at is not None and self._raster_match_at < until:
            self.irq_latch |= IRQ_RASTER
            self._raster_match_at = None
        self.synced = until
        self._refresh_irq_next()

    def _fetch(self) -> None:
        """Take what the VIC-II fetches from memory as it stands now (docs/vic.md, "The VIC-II reads
        memory": once per raster line where sprites draw, and after every register write)."""
        state = self.fetcher.state_for(self.state, self.registers)
        if state is not self.state:
            self.state = state
            self._schedule = self._schedule_for(state)

    # ---- the CPU's lines ---------------------------------------------------------------------

    def _refresh_irq_next(self) -> None:
        enabled = self.registers[REG_IRQ_ENABLE] & IRQ_SOURCES
        if self.irq_latch & enabled:
            self.irq_next = -NEVER  # low now
            return
        frame_cycles = self.video.frame_cycles
        after = self.synced
        candidates = []
        raster = raster_irq_time(self.video, self.registers)
        if enabled & IRQ_RASTER and raster is not None:
            candidates.append(after + (raster - after) % frame_cycles)
        if enabled & IRQ_RASTER and self._raster_match_at is not None:
            candidates.append(self._raster_match_at)
        events = self._schedule
        if enabled & IRQ_SPRITE_SPRITE and not self.sprite_sprite:
            candidates.append(_next_event(events.ss_times, after, frame_cycles))
        if enabled & IRQ_SPRITE_BACKGROUND and not self.sprite_background:
            candidates.append(_next_event(events.sb_times, after, frame_cycles))
        self._next_latch_at = NEVER
        if self._latching:  # a sampled bit may change the schedules there: ask again then
            point = self._next_latch_point(max(after, self._sampled_until), after + 2 * frame_cycles)
            self._next_latch_at = NEVER if point is None else point
            candidates.append(point)
        found = [c for c in candidates if c is not None]
        self.irq_next = self.start_cycle + min(found) if found else NEVER

    @property
    def bus(self):
        """The BA schedule of the current register state (retro.chips.vic.dma.BusSchedule)."""
        return self._bus

    def catch_up(self, cycle: int) -> None:
        """Apply everything the beam draws before machine cycle `cycle` (the state a report shows)."""
        self._advance(self.time(cycle))

    def irq_low(self, cycle: int) -> bool:
        self._advance(self.time(cycle) + 1)
        return bool(self.irq_latch & self.registers[REG_IRQ_ENABLE] & IRQ_SOURCES)

    def nmi_edge(self, cycle: int) -> bool:
        return False

    def ba_wait(self, cycle: int) -> int:
        t = cycle - self.start_cycle
        if t >= self._next_latch_at:  # the BA schedule changes there (see _latch)
            self._advance(t)
        return self._bus.wait[t % self.video.frame_cycles] if t >= 0 else 0

    def ba_free(self, cycle: int) -> int:
        t = cycle - self.start_cycle
        if t >= self._next_latch_at:
            self._advance(t)
        if t < 0:
            return -t + self._bus.free[0]
        return self._bus.free[t % self.video.frame_cycles]

    def time(self, cycle: int) -> int:
        return cycle - self.start_cycle

    def beam(self, cycle: int) -> tuple[int, int, int]:
        """(frame, line, cycle in line) at a machine cycle."""
        return position(self.video, self.time(cycle))

    # ---- the bus -----------------------------------------------------------------------------

    def read(self, address: int, cycle: int) -> int:
        t = self.time(cycle)
        self._advance(t)
        register = address % MIRROR_SIZE
        if self.fetcher is not None and register in READ_ONLY_LATCHES:
            self.fetcher.check_latch(VIC_BASE + register, self.registers[REG_SPRITE_ENABLE])
        if register == REG_SPRITE_SPRITE:
            value, self.sprite_sprite = self.sprite_sprite, 0
            self._refresh_irq_next()
            return value
        if register == REG_SPRITE_BACKGROUND:
            value, self.sprite_background = self.sprite_background, 0
            self._refresh_irq_next()
            return value
        return self._value(register, t)

    def _value(self, register: int, t: int) -> int:
        if register >= REGISTER_COUNT:
            return UNUSED_READ
        if register in (REG_CONTROL1, REG_RASTER):
            line = self._raster_line(t)
            if register == REG_RASTER:
                return line & Y_COMPARE_MASK
            return (self.registers[REG_CONTROL1] & ~CONTROL1_RST8) | (CONTROL1_RST8 if line > Y_COMPARE_MASK else 0)
        if register == REG_IRQ_LATCH:
            return irq_register(self.irq_latch, self.registers[REG_IRQ_ENABLE])
        return self.registers[register] | UNUSED_BITS.get(register, 0)

    def _raster_line(self, t: int) -> int:
        """The raster counter at device time t (what $D012 and $D011 bit 7 read)."""
        _, line, cycle = position(self.video, max(t, 0))
        if line == 0 and cycle <= RASTER_IRQ_LINE0_DELAY:
            line = self.video.lines - 1  # the counter reaches 0 a cycle late (why line 0's IRQ is late)
        return line

    def write(self, address: int, value: int, cycle: int) -> None:
        t = self.time(cycle)
        register = address % MIRROR_SIZE
        # what is drawn up to and including this cycle used the old value; but $D01D/$D01C are taken
        # within the cycle: its first pixels are the old setting's in the switched rows (below)
        self._advance(t if register in _SWITCH_PIXEL else t + 1)
        if register >= REGISTER_COUNT or register in _READ_ONLY:
            return
        if register == REG_IRQ_LATCH:
            self.irq_latch &= ~value & IRQ_SOURCES
            self._refresh_irq_next()
            return
        old = self.registers[register]
        if register in _X_SET and old != value & 0xFF:
            self._hold_started_rows(register, value & 0xFF, t + 1)
        if register in _SWITCH_PIXEL and old != value & 0xFF:
            self._switch_rows_in_progress(register, value & 0xFF, t)
        old_compare = raster_compare_line(self.registers)
        self.registers[register] = value & 0xFF
        if old == value:
            return
        # The compare runs every cycle and latches on its change from no match to a match, so a
        # write that moves the compare line onto the current line latches now [VICE-src vicii-cycle.c]
        compare = raster_compare_line(self.registers)
        if compare != old_compare and compare == self._raster_line(t + 1):
            self._raster_match_at = t + 1  # the compare's cycle, as a raster event (seen after it)
        if register in _SAMPLED_SET:
            self._sample_within_line(t + 1)
        if register in _SAMPLED_SET or (self._latching and register in _COLLISION_SET | _DMA_SET):
            self._use_sampled()
        else:
            if register in _COLLISION_SET:
                self.state = self.state.with_registers(self.registers)
                self._schedule = self._schedule_for(self.state)
            if register in _DMA_SET:
                self._bus = bus_schedule(self.video, self.registers)
        if self.fetcher is not None:
            self._fetch()  # $D018, the mode bits and the enabled sprites change what it fetches
        self._refresh_irq_next()

    def peek(self, address: int) -> int:
        """The value a read would return at the last synchronised cycle, without clearing anything."""
        register = address % MIRROR_SIZE
        if register == REG_SPRITE_SPRITE:
            return self.sprite_sprite
        if register == REG_SPRITE_BACKGROUND:
            return self.sprite_background
        return self._value(register, self.synced)
