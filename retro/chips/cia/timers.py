"""CIA 1 at $DC00-$DCFF as a C64 program run needs it: its two interval timers counting phi2 and the
interrupt control register's flags [6526 data sheet; retro.chips.cia.constants].

What is modelled [6526, "Interval timers", "Control registers", "Interrupt control register"]:
- each timer is a 16-bit counter and a 16-bit latch: a write to the low or high byte sets the latch,
  a read gives the counter; the latch goes into the counter on an underflow, on a force load (control
  bit 4, a strobe that reads back 0), and when the high byte is written while the timer is stopped;
- control bit 0 starts and stops the timer; bit 3 picks one-shot (the underflow clears bit 0) or
  continuous mode; only counting phi2 (timer A: bit 5 = 0; timer B: bits 5-6 = 00);
- an underflow sets the timer's flag in the interrupt control register; reading it returns the
  flags (bit 7 when an enabled one is set) and clears them; writing it sets (bit 7 = 1) or clears
  the mask bits written as 1.

Where the data sheet is silent the model decides, and says so (docs/vic.md, "CIA 1"): the counter
goes down by one in every phi2 cycle after the write that starts it (or loads it), passes through 0
and underflows in the cycle after it shows 0, so a continuous timer's period is latch + 1 cycles.

Not modelled: the ports ($DC00-$DC03: keyboard, joysticks), the time-of-day clock, the serial
port, CNT and timer B counting timer A, the PB6/PB7 outputs, and the interrupt itself: CIA 1's IRQ
line is not wired to the CPU, so a program that would let a CIA 1 interrupt through (an enabled flag
with its timer running) stops with a RunError, as does a read of a register not modelled. Writes to
registers not modelled are kept and have no effect. After RUN both timers are stopped with no flag
and no interrupt enabled (the KERNAL's 60 Hz timer interrupt is not running here).
"""

from __future__ import annotations

from collections.abc import Callable

from retro.chips.cia.constants import (
    COUNTER_MASK,
    CR_FORCE_LOAD,
    CR_RUNMODE_ONE_SHOT,
    CR_START,
    CR_UNUSED_WHEN_READ,
    CRA_INMODE_CNT,
    CRB_INMODE_MASK,
    ICR_SET,
    ICR_SOURCES,
    ICR_TIMER_A,
    ICR_TIMER_B,
    REG_CRA,
    REG_CRB,
    REG_ICR,
    REG_TIMER_A_HI,
    REG_TIMER_A_LO,
    REG_TIMER_B_HI,
    REG_TIMER_B_LO,
    REGISTERS,
)
from retro.errors import RunError


class IntervalTimer:
    """One 6526 interval timer counting phi2 cycles (module docstring), evaluated lazily: `counter`
    is its value at cycle `since`, from which it counts down while `running`."""

    def __init__(self, name: str, flag: int) -> None:
        self.name = name
        self.flag = flag  # its bit in the interrupt control register
        self.latch = COUNTER_MASK  # the data sheet's power-on value of both latches
        self.counter = 0
        self.since = 0
        self.running = False
        self.one_shot = False
        self.control = 0

    def at(self, cycle: int) -> tuple[int, bool, bool]:
        """(counter, whether it underflowed since `since`, whether it is still running) at `cycle`."""
        elapsed = cycle - self.since
        if not self.running or elapsed <= self.counter:
            return (self.counter - elapsed if self.running else self.counter), False, self.running
        if self.one_shot:
            return self.latch, True, False
        return self.latch - (elapsed - self.counter - 1) % (self.latch + 1), True, True

    def settle(self, cycle: int) -> bool:
        """Bring the timer to `cycle`; True when it underflowed on the way."""
        value, underflowed, running = self.at(cycle)
        self.counter, self.since, self.running = value, cycle, running
        if underflowed and not running:
            self.control &= ~CR_START
        return underflowed

    def write_latch(self, high: bool, value: int, cycle: int) -> None:
        if high:
            self.latch = (self.latch & 0x00FF) | value << 8
            if not self.running:  # "following a write to the high byte ... while the timer is stopped"
                self.counter = self.latch
        else:
            self.latch = (self.latch & 0xFF00) | value

    def write_control(self, value: int, cycle: int) -> None:
        """A write to CRA/CRB (the caller settled the timer to `cycle` first)."""
        if value & CR_FORCE_LOAD:
            self.counter = self.latch
        self.one_shot = bool(value & CR_RUNMODE_ONE_SHOT)
        self.running = bool(value & CR_START)
        self.since = cycle
        self.control = value & ~CR_UNUSED_WHEN_READ & 0xFF


class Cia1Timers:
    """CIA 1's registers at $DC00-$DCFF (module docstring). `clock()`: the machine cycle now, for
    `peek`, which has none."""

    def __init__(self, clock: Callable[[], int] = lambda: 0) -> None:
        self.clock = clock
        self.timer_a = IntervalTimer("timer A", ICR_TIMER_A)
        self.timer_b = IntervalTimer("timer B", ICR_TIMER_B)
        self.flags = 0
        self.mask = 0
        self.kept = bytearray(REGISTERS)  # what was written to registers not modelled

    def _settle(self, cycle: int) -> None:
        for timer in (self.timer_a, self.timer_b):
            if timer.settle(cycle):
                self.flags |= timer.flag

    def _timer(self, register: int) -> IntervalTimer:
        return self.timer_a if register in (REG_TIMER_A_LO, REG_TIMER_A_HI, REG_CRA) else self.timer_b

    def read(self, address: int, cycle: int) -> int:
        register = address % REGISTERS
        self._settle(cycle)
        if register in (REG_TIMER_A_LO, REG_TIMER_B_LO):
            return self._timer(register).counter & 0xFF
        if register in (REG_TIMER_A_HI, REG_TIMER_B_HI):
            return self._timer(register).counter >> 8
        if register == REG_ICR:
            value = self.flags | (ICR_SET if self.flags & self.mask else 0)
            self.flags = 0
            return value
        if register in (REG_CRA, REG_CRB):
            return self._timer(register).control
        raise RunError(f"the program read CIA 1 at ${address:04X}: retro models only CIA 1's timers, their control "
                       f"registers and the interrupt flags ($DC04-$DC07, $DC0D-$DC0F), not its ports (keyboard, "
                       f"joysticks), time-of-day clock or serial port")

    def write(self, address: int, value: int, cycle: int) -> None:
        register = address % REGISTERS
        value &= 0xFF
        self._settle(cycle)
        if register in (REG_TIMER_A_LO, REG_TIMER_A_HI, REG_TIMER_B_LO, REG_TIMER_B_HI):
            self._timer(register).write_latch(register in (REG_TIMER_A_HI, REG_TIMER_B_HI), value, cycle)
        elif register == REG_ICR:
            self.mask = self.mask | value & ICR_SOURCES if value & ICR_SET else self.mask & ~value & ICR_SOURCES
        elif register in (REG_CRA, REG_CRB):
            other_input = value & (CRA_INMODE_CNT if register == REG_CRA else CRB_INMODE_MASK)
            timer = self._timer(register)
            if other_input and value & CR_START:
                raise RunError(f"the program started CIA 1's {timer.name} counting other than phi2 (${address:04X} = "
                               f"${value:02X}): retro models only timers counting phi2 cycles")
            timer.write_control(value, cycle)
        else:
            self.kept[register] = value
            return
        self._refuse_interrupt(address, value)

    def _refuse_interrupt(self, address: int, value: int) -> None:
        """CIA 1's IRQ line is not wired to the CPU: a source that could pull it is refused."""
        for timer in (self.timer_a, self.timer_b):
            if self.mask & timer.flag and (timer.running or self.flags & timer.flag):
                raise RunError(f"${address:04X} = ${value:02X} lets CIA 1's {timer.name} interrupt the CPU: retro does "
                               f"not model CIA interrupts (docs/vic.md, \"CIA 1\")")

    def peek(self, address: int) -> int:
        register = address % REGISTERS
        cycle = self.clock()
        if register in (REG_TIMER_A_LO, REG_TIMER_A_HI, REG_TIMER_B_LO, REG_TIMER_B_HI):
            value = self._timer(register).at(cycle)[0]
            return value >> 8 if register in (REG_TIMER_A_HI, REG_TIMER_B_HI) else value & 0xFF
        if register == REG_ICR:
            flags = self.flags | sum(t.flag for t in (self.timer_a, self.timer_b) if t.at(cycle)[1])
            return flags | (ICR_SET if flags & self.mask else 0)
        if register in (REG_CRA, REG_CRB):
            timer = self._timer(register)
            return timer.control if timer.at(cycle)[2] or not timer.running else timer.control & ~CR_START
        return self.kept[register]
