"""6526 CIA numbers, each named once.

Sources:
- [6526] MOS Technology, "6526 Complex Interface Adapter (CIA)" data sheet (Commodore, 11/81):
  register map, "Interval timers (Timer A, Timer B)", "Interrupt control register", "Control
  registers" (the same text as the Amiga Hardware Reference Manual's 8520 chapter).
- [Mapping] S. Leemon, "Mapping the Commodore 64" (Compute!, 1984): $DC00-$DCFF (CIA 1), $DC0E/$DC0F
  default value $08.
"""

from __future__ import annotations

CIA1_BASE = 0xDC00  # CIA 1: keyboard, joysticks, the KERNAL's timer IRQ [Mapping]
CIA1_LAST = 0xDCFF  # its 16 registers repeat through $DC00-$DCFF
REGISTERS = 16

# register offsets [6526 register map]
REG_TIMER_A_LO, REG_TIMER_A_HI = 0x04, 0x05  # read: the counter; write: the latch
REG_TIMER_B_LO, REG_TIMER_B_HI = 0x06, 0x07
REG_ICR = 0x0D  # interrupt control: read the flags (clears them), write the mask
REG_CRA, REG_CRB = 0x0E, 0x0F  # control registers A and B

# control register bits [6526, "Control registers"]
CR_START = 0x01  # 1 = the timer counts; cleared by the underflow in one-shot mode
CR_RUNMODE_ONE_SHOT = 0x08  # 1 = one-shot, 0 = continuous
CR_FORCE_LOAD = 0x10  # a strobe: the latch goes into the counter; reads back 0
CRA_INMODE_CNT = 0x20  # timer A counts CNT transitions instead of phi2
CRB_INMODE_MASK = 0x60  # timer B: 00 phi2, 01 CNT, 10 timer A underflows, 11 those while CNT is high
CR_UNUSED_WHEN_READ = CR_FORCE_LOAD  # "bit 4 will always read back a zero"
CR_AFTER_IOINIT = 0x08  # $DC0E/$DC0F after the KERNAL's IOINIT [Mapping, $DC0E]

# interrupt control register [6526, "Interrupt control register"]
ICR_TIMER_A = 0x01
ICR_TIMER_B = 0x02
ICR_SOURCES = 0x1F  # TA, TB, TOD alarm, serial port, FLAG
ICR_SET = 0x80  # written: 1 sets the mask bits written as 1, 0 clears them; read: IR, an enabled flag is set

COUNTER_MASK = 0xFFFF
