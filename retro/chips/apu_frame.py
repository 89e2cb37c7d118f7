"""The one part of the NES APU modelled: the frame counter's interrupt (no sound, length counters or DMC).

What a program sees (nesdev wiki "APU Frame Counter" and "APU" ($4015); blargg's
`blargg_apu_2005.07.30` readme.txt and tests.txt, which time it against the $4017 write cycle):
- `$4017` write: bit 7 the mode (0: the 4-step sequence, the only one that sets the flag; 1: the
  5-step sequence, never), bit 6 the IRQ inhibit. Setting the inhibit clears the frame interrupt
  flag at once; clearing it leaves the flag as it is. The sequence restarts a few cycles after the
  write: the old one runs on until then (`RESTART_DELAY` after the write cycle), and the new one's
  flag is set in `FLAG_SET_CYCLES` cycles in a row from `FIRST_FLAG_AFTER_WRITE` cycles after the
  write cycle, then every `FOUR_STEP_PERIOD` cycles. A write between two APU cycles starts the mode
  a cycle later (`ODD_WRITE_DELAY`; blargg, "Clock Jitter"). APU cycles are every other CPU cycle,
  in the phase `APU_CYCLE_PARITY` names (the same clock as OAM DMA's odd/even cycles).
- `$4015` read: bit 6 the frame interrupt flag; the read clears it, unless the flag is set in that
  very cycle (nesdev wiki "APU", Status: "it will read back as 1 but it will not be cleared"): two reads in
  a row can both see it (blargg: "always read $4015 an extra time after the flag is found to be set").
  Other bits read 0 (no length counter runs, no DMC).
- The flag drives the CPU's IRQ line (low while set), from `IRQ_LINE_DELAY` cycles after it is set.
- Power-on: as if $00 had been written to `$4017` `POWER_ON_WRITE_LEAD` cycles before the first
  instruction (blargg: "9 to 12 clocks", "a 10 clock delay" in his example).
Timing is NTSC (the console runs NTSC cartridges). Nothing is stepped: the flag at any cycle is
computed from the last writes and reads, and the IRQ line's next low cycle is kept as the CPU's
lower bound (`irq_next`), so a program that never enables the frame IRQ pays one comparison per
unmasked interrupt poll.
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.cpu.bus import NEVER

STATUS_FRAME_IRQ = 0x40            # $4015 bit 6
MODE_FIVE_STEP = 0x80              # $4017 bit 7
IRQ_INHIBIT = 0x40                 # $4017 bit 6
# nesdev wiki "APU Frame Counter": "After 3 or 4 CPU clock cycles, the timer is reset" (3 when the
# write lands during an APU cycle, 4 between two), and the 4-step sequence sets the flag at CPU
# cycles 29828, 29829 and 29830 (= 0 of the next sequence) after the reset, one sequence being
# 29830 cycles (14915 APU cycles). So the flag is first set 3 + 29828 = 29831 cycles after the write
# cycle: blargg's tests.txt, 07.irq_flag_timing: "set three times in a row 29831 clocks after writing
# $4017 with $00"; 08.irq_timing: "IRQ handler is invoked at minimum 29833 clocks after writing $00".
RESTART_DELAY = 3
FLAG_AFTER_RESTART = 29828
FIRST_FLAG_AFTER_WRITE = RESTART_DELAY + FLAG_AFTER_RESTART
FLAG_SET_CYCLES = 3
FOUR_STEP_PERIOD = 29830
ODD_WRITE_DELAY = 1                # a write between APU cycles: the reset (and every step) a cycle later
# The CPU cycles an APU cycle begins with, as (cycle - origin) % 2 with the PPU's clock origin: those
# on which an OAM DMA write costs 514 cycles (retro.chips.ppu.device). blargg's cpu_interrupts_v2
# 4-irq_and_dma, which times a frame IRQ against OAM DMA, passes with this phase, fails with the other.
APU_CYCLE_PARITY = 1
IRQ_LINE_DELAY = 0                 # a poll in the cycle the flag is set sees the line low (08.irq_timing)
POWER_ON_WRITE_LEAD = 10           # power-on's implied $4017 = $00 write, cycles before the first instruction


@dataclass(frozen=True)
class _Sequence:
    """One run of the sequencer: its first flag-setting cycle (None: the 5-step mode, no flag) and
    the cycle a later write's restart ends it (NEVER while it runs)."""

    first_flag: int | None
    until: int = NEVER

    def next_flag(self, cycle: int) -> int:
        """The first cycle >= `cycle` in which this run sets the flag (NEVER: none)."""
        first = self.first_flag
        if first is None:
            return NEVER
        if cycle <= first:
            found = first
        else:
            periods, into = divmod(cycle - first, FOUR_STEP_PERIOD)
            found = cycle if into < FLAG_SET_CYCLES else first + (periods + 1) * FOUR_STEP_PERIOD
        return found if found < self.until else NEVER


class FrameCounter:
    """What `$4015` reads and `$4017` writes reach (the console's I/O device routes them); the frame IRQ through `lines`, the
    machine's `retro.cpu.bus.CpuLines` (the PPU), whose `irq_next` it keeps and whose `irq_low`
    asks it. `origin`: the machine cycle parity is counted from; `first_instruction`: the cycle the
    CPU starts at (power-on's implied write comes `POWER_ON_WRITE_LEAD` before it)."""

    def __init__(self, lines, origin: int, first_instruction: int) -> None:
        self.lines = lines
        self.origin = origin
        self.inhibit = False
        self.enabled_from = -NEVER     # sets before this cycle (inhibited then) do not count
        self.cleared_at = -NEVER       # the last cycle that cleared the flag
        self.previous = _Sequence(None)
        self.current = _Sequence(None)
        self.write_mode(0x00, first_instruction - POWER_ON_WRITE_LEAD)
        self.seen = first_instruction

    # ---- the flag -------------------------------------------------------------------------------

    def _next_flag(self, cycle: int) -> int:
        """The first cycle >= `cycle` in which the flag is set (NEVER: none while the state holds)."""
        if self.inhibit:
            return NEVER
        cycle = max(cycle, self.enabled_from)
        return min(self.previous.next_flag(cycle), self.current.next_flag(cycle))

    def flag(self, cycle: int) -> bool:
        """The frame interrupt flag as a read in `cycle` sees it (no side effect)."""
        return self._next_flag(self.cleared_at + 1) <= cycle

    def _refresh_irq_next(self) -> None:
        self.lines.irq_next = self._next_flag(self.cleared_at + 1) + IRQ_LINE_DELAY

    def irq_low(self, cycle: int) -> bool:
        """Whether the IRQ line is low in `cycle` (the CPU polls it)."""
        self.seen = cycle
        return self.flag(cycle - IRQ_LINE_DELAY)

    # ---- the registers (the console's I/O device, retro.machines.nes, routes them here) ----------

    def read_status(self, cycle: int) -> int:
        """A `$4015` read in `cycle`: the frame bit (other bits 0), and the flag cleared unless it
        is set in this very cycle."""
        self.seen = cycle
        value = STATUS_FRAME_IRQ if self.flag(cycle) else 0
        self.cleared_at = cycle - 1 if self._next_flag(cycle) == cycle else cycle
        self._refresh_irq_next()
        return value

    def peek_status(self) -> int:
        """`$4015` as a debugger sees it: the frame bit at the last cycle the counter was told of."""
        return STATUS_FRAME_IRQ if self.flag(self.seen) else 0

    def write_mode(self, value: int, cycle: int) -> None:
        """A `$4017` write in `cycle` (module docstring)."""
        self.seen = cycle
        odd = (cycle - self.origin - APU_CYCLE_PARITY) % 2
        restart = cycle + RESTART_DELAY + odd * ODD_WRITE_DELAY
        # the running sequence shows through until the restart (blargg: the new mode's first clocks)
        self.previous = _Sequence(self.current.first_flag, restart)
        first = None if value & MODE_FIVE_STEP else cycle + FIRST_FLAG_AFTER_WRITE + odd * ODD_WRITE_DELAY
        self.current = _Sequence(first)
        if value & IRQ_INHIBIT:
            self.inhibit = True
            self.cleared_at = cycle
        elif self.inhibit:
            self.inhibit = False
            self.enabled_from = cycle
        self._refresh_irq_next()
