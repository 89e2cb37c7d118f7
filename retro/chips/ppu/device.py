"""The PPU as a bus device of the 2A03 machine: registers at $2000-$3FFF and OAM DMA at $4014.

What a program sees (nesdev wiki "PPU registers", "PPU scrolling", "PPU frame timing"):
- $2000-$2007 repeat every 8 bytes up to $3FFF.
- $2002 returns vblank (bit 7), sprite-zero hit (bit 6), sprite overflow (bit 5) and the
  I/O latch in bits 0-4. Reading it clears bit 7 and the $2005/$2006 write toggle, never bit 6.
  The vblank flag is set at line 241 dot 1; vblank and hit are cleared at dot 1 of the pre-render
  line. The hit flag is set at the dot the hit model (`retro.chips.ppu.hit`) gives.
- $2000/$2005/$2006 load the internal t/x/w registers; $2006's second write copies t to v; $2007
  reads (buffered, except the palette) and writes VRAM at v, then adds 1 or 32 ($2000 bit 2).
- VRAM: $0000-$1FFF pattern tables (the scene's CHR, writable like CHR RAM), $2000-$2FFF the
  four nametables folded onto 2 KiB by the mirroring, $3000-$3EFF a mirror, $3F00-$3F1F palette
  ($3F10/$14/$18/$1C mirror $3F00/$04/$08/$0C).
- $4014: OAM DMA copies the 256 bytes of page N to OAM starting at OAMADDR and stalls the CPU
  513 cycles, 514 when the write lands on an odd CPU cycle.
The PPU clock follows `retro.chips.ppu.clock`. The frame's scroll is taken from t and x, which the
real PPU copies into v during the pre-render line (vertical) and at dot 257 of each line
(horizontal); writes during lines 0-239 take effect for the pixels after the write, as if the new
state held for the whole frame (the real PPU's mid-frame v/t details are not modelled, nor is the
power-up write lock-out). The NMI output, the $2002 read racing the vblank flag and the odd-frame
skip follow the rules of docs/nes.md, "The vblank and NMI timeline"; sprite overflow follows
`retro.chips.ppu.overflow`, recomputed like the hit whenever OAM, $2000 or $2001 change.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from retro.chips.ppu.clock import dots_at_cycle, first_cycle_seeing, frame_dots, line_and_dot
from retro.chips.ppu.constants import (
    CHR_SIZE,
    COARSE_SHIFT,
    CTRL_INCREMENT_32,
    CTRL_NAMETABLE,
    CTRL_NMI,
    CTRL_SPRITE_8X16,
    DOTS_PER_LINE,
    FINE_SCROLL,
    FLAG_CLEAR_DOT,
    MASK_RENDERING,
    MIRRORING,
    NAMETABLE_SIZE,
    NMI_SAMPLE_DOT_OFFSET,
    NAMETABLE_SPACE_MASK,
    OAM_DMA_CYCLES,
    OAM_DMA_ODD_EXTRA,
    OAM_SIZE,
    OAMADDR,
    OAMDATA,
    OAMDMA,
    ODD_FRAME_DECISION_DOT,
    PALETTE_BASE,
    PALETTE_SHADOW_OFFSET,
    PALETTE_SIZE,
    PPU_REGISTER_BASE,
    PPU_REGISTER_MASK,
    PPUADDR,
    PPUADDR_HIGH_BITS,
    PPUCTRL,
    PPUDATA,
    PPUMASK,
    PPUSCROLL,
    PPUSTATUS,
    SCREEN_HEIGHT,
    STATUS_OPEN_BUS,
    STATUS_OVERFLOW,
    STATUS_SPRITE0_HIT,
    STATUS_VBLANK,
    V_BITS,
    V_COARSE_X,
    V_COARSE_Y,
    V_COARSE_Y_SHIFT,
    V_FINE_Y,
    V_FINE_Y_SHIFT,
    V_NAMETABLE,
    V_NAMETABLE_SHIFT,
    VBLANK_DOT,
    VBLANK_SUPPRESSING_READ,
    VBLANK_LINE,
    VRAM_ADDRESS_MASK,
    VideoStandard,
)
from retro.chips.ppu.overflow import overflow_dots
from retro.chips.ppu.hit import hit_dot, hit_pixels, rendering_enabled_for_hits
from retro.chips.ppu.state import PpuState
from retro.cpu.bus import NEVER

PAGE_SIZE = 0x100
INCREMENT_ACROSS = 1
INCREMENT_DOWN = 32
PALETTE_MIRROR_MASK = 0x13          # $3F10/$14/$18/$1C -> $3F00/$04/$08/$0C
PALETTE_MIRRORED = 0x10




class PpuDevice:
    """The PPU on the bus, created from a PpuState; `retro.machines.nes.build_nes` maps it on a 2A03's bus."""

    chip_name = "PPU"
    drives_cpu_lines = True
    # The PPU has no IRQ output, but it is the machine's one CpuLines: on a console the APU's frame
    # counter (`retro.chips.apu_frame`, set as `irq_source`) drives the IRQ input through it and
    # keeps `irq_next` (an instance attribute then); without one the line never goes low.
    irq_next = NEVER
    irq_source = None

    def __init__(self, state: PpuState | None = None, *, origin: int = 0,
                 read_memory: Callable[[int], int] | None = None,
                 stall: Callable[[int], None] | None = None, chr_writable: bool = True) -> None:
        state = state or PpuState()
        self.chr_writable = chr_writable  # False for a cartridge's CHR ROM: $2007 writes there do nothing
        self.video: VideoStandard = state.video
        self.mirroring = state.mirroring
        self.ctrl = state.ctrl
        self.mask = state.mask
        self.oam = bytearray(state.oam)
        self.chr = bytearray(state.chr)
        self.ciram = bytearray(state.ciram)
        self.palette = bytearray(PALETTE_SIZE)
        self.t = ((state.ctrl & CTRL_NAMETABLE) << V_NAMETABLE_SHIFT) | self._scroll_bits(state.scroll_x, state.scroll_y)
        self.fine_x = state.scroll_x & FINE_SCROLL
        self.v = self.t
        self.w = 0
        self.oam_addr = 0
        self.read_buffer = 0
        self.latch = 0
        self.vblank = False
        self.sprite0_hit = False
        self.sprite_overflow = False
        self.read_memory = read_memory or (lambda address: 0)
        self.stall = stall or (lambda cycles: None)
        self.dma_stalled = 0            # CPU cycles OAM DMA has held the CPU so far
        # clock
        self.origin = origin
        self.frame = 0
        self.frame_start = 0            # absolute dot of (line 0, dot 0) of the current frame
        self.position = 0               # absolute dot up to which events have been applied
        self.frame_length = self.video.dots_per_frame
        self._event = 0                 # index into _fixed_events of the next one
        self._state_from = -1           # absolute dot of the last change that can move the hit
        self._candidates: np.ndarray | None = None
        # ((frame_start, _state_from), the next overflow dot): valid until OAM, $2000/$2001 or the frame change
        self._overflow_next: tuple[tuple[int, int], int | None] | None = None
        self.hits: list[tuple[int, int, int]] = []   # (frame, line, dot) of each hit, for inspection
        self.overflows: list[tuple[int, int, int]] = []  # (frame, line, dot) of each overflow flag
        # The NMI output is low while the vblank flag and $2000 bit 7 are both set. The CPU samples it
        # once a cycle (NMI_SAMPLE_DOT_OFFSET dots after the dot its reads see); an edge counts once a
        # sample sees the output low, so output that goes high again at or before that sample is lost.
        self.nmi_pending = False        # an edge the CPU has sampled (or will, unless the output goes high first)
        self.nmi_edge_cycle = -NEVER    # the CPU cycle whose sample sees it: a poll before it does not
        self._nmi_sample_dot = -NEVER   # the absolute dot of that sample
        self._vblank_suppressed = False  # a $2002 read just before the vblank dot keeps the flag from being set
        self.nmi_next = NEVER
        pre = self.video.pre_render_line
        self._fixed_events = [
            (VBLANK_LINE * DOTS_PER_LINE + VBLANK_DOT, self._set_vblank),
            (pre * DOTS_PER_LINE + FLAG_CLEAR_DOT, self._clear_flags),
            (pre * DOTS_PER_LINE + ODD_FRAME_DECISION_DOT, self._decide_frame_length),
            (None, self._next_frame),   # at frame_length
        ]

    # ---- state as the hit model sees it ------------------------------------------------------

    @staticmethod
    def _scroll_bits(scroll_x: int, scroll_y: int) -> int:
        return ((scroll_x >> COARSE_SHIFT) | ((scroll_y >> COARSE_SHIFT) << V_COARSE_Y_SHIFT)
                | ((scroll_y & FINE_SCROLL) << V_FINE_Y_SHIFT))

    def state(self) -> PpuState:
        """The PPU state the current frame renders with (scroll from t and fine x)."""
        t = self.t
        scroll_x = ((t & V_COARSE_X) << COARSE_SHIFT) | self.fine_x
        scroll_y = (((t & V_COARSE_Y) >> V_COARSE_Y_SHIFT) << COARSE_SHIFT) | ((t & V_FINE_Y) >> V_FINE_Y_SHIFT)
        ctrl = (self.ctrl & ~CTRL_NAMETABLE) | ((t & V_NAMETABLE) >> V_NAMETABLE_SHIFT)
        return PpuState(ctrl=ctrl, mask=self.mask, scroll_x=scroll_x, scroll_y=scroll_y, mirroring=self.mirroring,
                        video=self.video, oam=bytes(self.oam), chr=bytes(self.chr), ciram=bytes(self.ciram))

    def _changed(self, dot: int) -> None:
        self._state_from = dot
        self._candidates = None
        self._overflow_next = None

    # ---- clock -------------------------------------------------------------------------------

    def dot_of(self, cycle: int) -> int:
        return dots_at_cycle(cycle, self.origin, self.video)

    def where(self) -> tuple[int, int, int]:
        """(frame, line, dot) of the last access."""
        line, dot = line_and_dot(self.position - self.frame_start)
        return self.frame, line, dot

    def _next_hit(self) -> int | None:
        if self.sprite0_hit or self._event > 0:
            return None                  # already hit, or past the vblank line (no visible line left)
        if not rendering_enabled_for_hits(self.mask):
            return None
        if self.position - self.frame_start >= SCREEN_HEIGHT * DOTS_PER_LINE:
            return None                  # no visible line left in this frame
        if self._candidates is None:
            lines, xs = hit_pixels(self.state())
            self._candidates = lines * DOTS_PER_LINE + hit_dot(xs)
        later = self._candidates[self._candidates > self._state_from - self.frame_start]
        return int(later[0]) + self.frame_start if later.size else None

    def _next_overflow(self) -> int | None:
        if self.sprite_overflow or self._event > 0 or not self.mask & MASK_RENDERING:
            return None
        key = (self.frame_start, self._state_from)
        if self._overflow_next is None or self._overflow_next[0] != key:
            dots = overflow_dots(bytes(self.oam), bool(self.ctrl & CTRL_SPRITE_8X16))
            later = dots[dots > self._state_from - self.frame_start]
            self._overflow_next = (key, int(later[0]) + self.frame_start if later.size else None)
        return self._overflow_next[1]

    def advance(self, target: int) -> None:
        """Apply every PPU event at absolute dots <= target."""
        while True:
            offset, action = self._fixed_events[self._event]
            fixed_at = self.frame_start + (self.frame_length if offset is None else offset)
            flag_at, flag = min(((at, flag) for at, flag in ((self._next_hit(), "sprite0_hit"),
                                                             (self._next_overflow(), "sprite_overflow"))
                                 if at is not None), default=(None, None))
            if flag_at is not None and flag_at <= fixed_at:
                if flag_at > target:
                    break
                setattr(self, flag, True)   # a sprite flag raised mid-frame: (frame, line, dot) kept for inspection
                (self.hits if flag == "sprite0_hit" else self.overflows).append(
                    (self.frame, *line_and_dot(flag_at - self.frame_start)))
                continue
            if fixed_at > target:
                break
            self._event += 1
            action(fixed_at)
        self.position = max(self.position, target)

    def _set_vblank(self, dot: int) -> None:
        if self._vblank_suppressed:
            self._vblank_suppressed = False
            return
        self.vblank = True
        if self.ctrl & CTRL_NMI:
            self._nmi_output_low(dot)

    def _nmi_output_low(self, dot: int) -> None:
        """The NMI output fell at absolute dot `dot`: the first CPU sample at or after it sees the edge."""
        cycle = first_cycle_seeing(dot - NMI_SAMPLE_DOT_OFFSET, self.origin, self.video)
        self.nmi_pending = True
        self.nmi_edge_cycle = cycle
        self._nmi_sample_dot = self.dot_of(cycle) + NMI_SAMPLE_DOT_OFFSET
        self._refresh_nmi_next()

    def _nmi_output_high(self, dot: int) -> None:
        """The NMI output rose at `dot` (flag cleared or NMI disabled): an edge not sampled by then is lost."""
        if self.nmi_pending and dot <= self._nmi_sample_dot:
            self.nmi_pending = False
            self._refresh_nmi_next()

    def _vblank_dot(self) -> int:
        """The absolute dot of this frame's vblank flag."""
        return self.frame_start + VBLANK_LINE * DOTS_PER_LINE + VBLANK_DOT

    # ---- the CPU's lines ---------------------------------------------------------------------

    def start_clock(self, cycle: int) -> None:
        """Line 0, dot 0 of the first frame is machine cycle `cycle` (the machine's clock when mapped)."""
        self.origin = cycle
        self._refresh_nmi_next()

    # fields a snapshot leaves shared: the bus's callbacks, and arrays the device replaces, never mutates
    _SHARED = frozenset({"read_memory", "stall", "irq_source", "_candidates", "_fixed_events", "video"})

    def snapshot(self) -> dict:
        """Everything the device holds now, as a copy `restore` can go back to (any number of times)."""
        return {name: (value.copy() if name not in self._SHARED and isinstance(value, (bytearray, list)) else value)
                for name, value in vars(self).items() if name != "_fixed_events"}

    def restore(self, snapshot: dict, origin: int) -> None:
        """Back to `snapshot` with the clock's origin moved to machine cycle `origin` (every position in
        the snapshot counts dots from its origin, so the beam stands where it stood relative to it)."""
        for name, value in snapshot.items():
            setattr(self, name, value.copy() if name not in self._SHARED and isinstance(value, (bytearray, list))
                    else value)
        self.nmi_edge_cycle += origin - snapshot["origin"]  # the one field counted in machine cycles
        self.start_clock(origin)

    def _refresh_nmi_next(self) -> None:
        """The first CPU cycle whose poll can see an NMI edge: a pending edge's own cycle, else a lower
        bound on the next vblank flag's."""
        if self.nmi_pending:
            self.nmi_next = self.nmi_edge_cycle  # a poll before the edge's own cycle does not see it
        elif not self.ctrl & CTRL_NMI:
            self.nmi_next = NEVER
        else:
            # this frame's vblank, or (past it) the next frame's, at most one dot early (the odd-frame skip)
            dot = self._vblank_dot() + (0 if self._event == 0 else self.frame_length - 1)
            self.nmi_next = first_cycle_seeing(dot - NMI_SAMPLE_DOT_OFFSET, self.origin, self.video)

    def nmi_edge(self, cycle: int) -> bool:
        """Whether the CPU's poll at `cycle` (never before `nmi_next`) sees an NMI edge; it is taken."""
        self.advance(self.dot_of(cycle) + NMI_SAMPLE_DOT_OFFSET)
        if not self.nmi_pending or self.nmi_edge_cycle > cycle:
            return False
        self.nmi_pending = False
        self._refresh_nmi_next()
        return True

    def irq_low(self, cycle: int) -> bool:
        source = self.irq_source
        return source is not None and source.irq_low(cycle)

    def ba_wait(self, cycle: int) -> int:
        return 0

    def ba_free(self, cycle: int) -> int:
        return NEVER  # OAM DMA stalls the CPU through `stall`, not through RDY timing

    def _clear_flags(self, dot: int) -> None:
        self.vblank = False
        self.sprite0_hit = False
        self.sprite_overflow = False
        self._vblank_suppressed = False
        self._nmi_output_high(dot)

    def _decide_frame_length(self, dot: int) -> None:
        self.frame_length = frame_dots(self.frame, bool(self.mask & MASK_RENDERING), self.video)

    def _next_frame(self, dot: int) -> None:
        self.frame += 1
        self.frame_start = dot
        self.frame_length = self.video.dots_per_frame
        self._event = 0

    # ---- bus interface -----------------------------------------------------------------------

    def read(self, address: int, cycle: int) -> int:
        if address == OAMDMA:
            return self.latch
        dot = self.dot_of(cycle)
        self.advance(dot)
        register = PPU_REGISTER_BASE | (address & PPU_REGISTER_MASK)
        if register == PPUSTATUS:
            value = self._status()
            if self.vblank:
                self.vblank = False
                self._nmi_output_high(dot)
            elif self._event == 0 and dot == self._vblank_dot() - VBLANK_SUPPRESSING_READ:
                self._vblank_suppressed = True
            self.w = 0
        elif register == OAMDATA:
            value = self.oam[self.oam_addr]
        elif register == PPUDATA:
            value = self._read_data()
        else:
            return self.latch            # write-only registers read back the latch
        self.latch = value
        return value

    def peek(self, address: int) -> int:
        if address == OAMDMA:
            return self.latch
        register = PPU_REGISTER_BASE | (address & PPU_REGISTER_MASK)
        if register == PPUSTATUS:
            return self._status()
        if register == OAMDATA:
            return self.oam[self.oam_addr]
        if register == PPUDATA:
            return self._vram_read(self.v) if self._is_palette(self.v) else self.read_buffer
        return self.latch

    def write(self, address: int, value: int, cycle: int) -> None:
        dot = self.dot_of(cycle)
        self.advance(dot)
        self.latch = value
        if address == OAMDMA:
            self._oam_dma(value, cycle)
            self._changed(dot)
            return
        register = PPU_REGISTER_BASE | (address & PPU_REGISTER_MASK)
        if register == PPUCTRL:
            enabled, self.ctrl = self.ctrl & CTRL_NMI, value
            if self.vblank and value & CTRL_NMI and not enabled:
                # the NMI output falls in the write's cycle: after the poll of the writing instruction
                # (its penultimate cycle), so the NMI follows the next instruction [blargg ppu_vbl_nmi
                # 04-nmi_control, test 11: "immediate occurrence should be after NEXT instruction"]
                self._nmi_output_low(dot)
            elif enabled and not value & CTRL_NMI:
                self._nmi_output_high(dot)
            self._refresh_nmi_next()
            self.t = (self.t & ~V_NAMETABLE) | ((value & CTRL_NAMETABLE) << V_NAMETABLE_SHIFT)
        elif register == PPUMASK:
            self.mask = value
        elif register == OAMADDR:
            self.oam_addr = value
            return
        elif register == OAMDATA:
            self.oam[self.oam_addr] = value
            self.oam_addr = (self.oam_addr + 1) & 0xFF
        elif register == PPUSCROLL:
            self._write_scroll(value)
        elif register == PPUADDR:
            self._write_address(value)
        elif register == PPUDATA:
            self._vram_write(self.v, value)
            self._step_v()
        else:
            return                        # $2002 is read-only
        self._changed(dot)

    # ---- registers ---------------------------------------------------------------------------

    def _status(self) -> int:
        return ((STATUS_VBLANK if self.vblank else 0) | (STATUS_SPRITE0_HIT if self.sprite0_hit else 0)
                | (STATUS_OVERFLOW if self.sprite_overflow else 0)
                | (self.latch & STATUS_OPEN_BUS))

    def _write_scroll(self, value: int) -> None:
        if self.w == 0:
            self.t = (self.t & ~V_COARSE_X) | (value >> COARSE_SHIFT)
            self.fine_x = value & FINE_SCROLL
        else:
            self.t = (self.t & ~(V_COARSE_Y | V_FINE_Y)) | self._scroll_bits(0, value)
        self.w ^= 1

    def _write_address(self, value: int) -> None:
        if self.w == 0:
            self.t = (self.t & 0x00FF) | ((value & PPUADDR_HIGH_BITS) << 8)
        else:
            self.t = (self.t & 0xFF00) | value
            self.v = self.t
        self.w ^= 1

    def _step_v(self) -> None:
        step = INCREMENT_DOWN if self.ctrl & CTRL_INCREMENT_32 else INCREMENT_ACROSS
        self.v = (self.v + step) & V_BITS

    def _read_data(self) -> int:
        address = self.v & VRAM_ADDRESS_MASK
        if self._is_palette(address):
            value = self._vram_read(address)
            self.read_buffer = self._vram_read(address - PALETTE_SHADOW_OFFSET)
        else:
            value, self.read_buffer = self.read_buffer, self._vram_read(address)
        self._step_v()
        return value

    @staticmethod
    def _is_palette(address: int) -> bool:
        return (address & VRAM_ADDRESS_MASK) >= PALETTE_BASE

    def _ciram_index(self, address: int) -> int:
        offset = address & NAMETABLE_SPACE_MASK
        page = MIRRORING[self.mirroring][offset // NAMETABLE_SIZE]
        return page * NAMETABLE_SIZE + offset % NAMETABLE_SIZE

    @staticmethod
    def _palette_index(address: int) -> int:
        index = address % PALETTE_SIZE
        return index & ~PALETTE_MIRRORED if index & PALETTE_MIRROR_MASK == PALETTE_MIRRORED else index

    def _vram_read(self, address: int) -> int:
        address &= VRAM_ADDRESS_MASK
        if address < CHR_SIZE:
            return self.chr[address]
        if address < PALETTE_BASE:
            return self.ciram[self._ciram_index(address)]
        return self.palette[self._palette_index(address)]

    def _vram_write(self, address: int, value: int) -> None:
        address &= VRAM_ADDRESS_MASK
        if address < CHR_SIZE:
            if self.chr_writable:
                self.chr[address] = value
        elif address < PALETTE_BASE:
            self.ciram[self._ciram_index(address)] = value
        else:
            self.palette[self._palette_index(address)] = value

    def _oam_dma(self, page: int, cycle: int) -> None:
        base = page * PAGE_SIZE
        for i in range(OAM_SIZE):
            self.oam[(self.oam_addr + i) & 0xFF] = self.read_memory(base + i)
        # odd or even counted from the clock's origin (retro.chips.ppu.clock): a call entered at a
        # given dot of the frame always meets the same parity
        stalled = OAM_DMA_CYCLES + (OAM_DMA_ODD_EXTRA if (cycle - self.origin) % 2 else 0)
        self.dma_stalled += stalled
        self.stall(stalled)
