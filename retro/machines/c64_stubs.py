"""The small stand-ins a C64 program run has for what retro does not emulate: CIA 1's timers and the
few BASIC and KERNAL ROM routines that test programs call. Each says what it models and what not.

There is no BASIC or KERNAL ROM in retro (docs/vic.md, "Running a C64 program"). A routine below is
a Python trap at its ROM address (retro.cpu.traps: the trap byte is written in the RAM under the ROM,
so a program that stores its own code there while the ROM is switched out replaces it): reached by
a JSR while the port at $01 maps the ROM in, it does what the routine does to the screen and the
work area the KERNAL keeps in RAM, then returns as the RTS would. It takes 6 cycles (the RTS's), far
fewer than the ROM's hundreds or thousands, and leaves A, X, Y and the flags as they were (the ROM
leaves them changed): the programs run them with interrupts off, outside their timed code.

- STROUT ($AB1E, BASIC: print the text at A/Y): the text up to a 0 or a quote [BASIC's STRLIT, as in
  Microsoft BASIC's source, mist64/msbasic string.s] goes to the screen editor below.
- LINPRT ($BDCD, BASIC: print the number A * 256 + X): in decimal after a space (FOUT writes the sign
  position first: a space for a number >= 0 [msbasic float.s, LINPRT and FOUT]).
- IOINIT ($FDA3, KERNAL: initialise the CIAs [Mapping the Commodore 64, $FDA3]): CIA 1's timers
  stopped and its interrupts masked, CIA 2's port A back to bank 0. Not its start of the 60 Hz timer
  interrupt (CIA interrupts are not modelled: retro.chips.cia.timers), nor the serial bus or SID.

The screen editor [Mapping the Commodore 64, $D1-$D6, $0286, $0288; C64 Programmer's Reference
Guide, appendix B (screen codes) and C (CHR$ codes)]: characters are written to the screen at $0400
(HIBASE $0288) and the current colour ($0286) to colour RAM, the cursor kept where the KERNAL keeps
it: row in $D6, column in $D3, the row's screen address in $D1/$D2 and colour RAM address in $F3/$F4
(programs write beside the cursor through them). Control codes: RETURN (13, 141: next row, reverse
and quote mode off), CLR (147), HOME (19), the four cursor moves, RVS ON/OFF (18, 146) and the
sixteen colour codes; printing past column 39 or below row 24 goes on at the next row, scrolling the
screen up. Not modelled (a RunError says so): other control codes (insert, delete, case switch...)
and control codes in quote mode; nor the editor's logical lines of two rows (a line past column 39
continues as a row of its own here) or the colour of cells CLR blanks (colour RAM is left as it was).
After RUN the cursor is home, the colour light blue (14), the screen as it was.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from retro.chips.cia.constants import CIA1_BASE, CIA1_LAST, CR_AFTER_IOINIT, ICR_SOURCES, REG_CRA, REG_CRB, REG_ICR
from retro.chips.cia.timers import Cia1Timers
from retro.chips.vic.constants import COLOR_RAM, TEXT_COLUMNS, TEXT_ROWS
from retro.cpu.machine import Machine
from retro.cpu.traps import TRAP_OPCODE, install_on_mpu
from retro.errors import RunError

STROUT = 0xAB1E
LINPRT = 0xBDCD
IOINIT = 0xFDA3
ROM_STUB_NAMES = {STROUT: "STROUT", LINPRT: "LINPRT", IOINIT: "IOINIT"}
STUB_CYCLES = 6  # the RTS that ends the routine; the ROM's own work is not timed
STRING_LIMIT = 255  # BASIC's strings are at most 255 characters long

# the screen editor's work area in RAM [Mapping the Commodore 64]
PNT = 0xD1  # $D1/$D2: the screen address of the cursor's row
PNTR = 0xD3  # cursor column
TBLX = 0xD6  # cursor row
USER = 0xF3  # $F3/$F4: the colour RAM address of the cursor's row
RVS = 0xC7  # reverse mode: nonzero = on
COLOR = 0x0286  # the colour printed characters get
HIBASE = 0x0288  # the page of the screen
KERNAL_COLOR, KERNAL_HIBASE = 0x0E, 0x04  # after the KERNAL's initialisation: light blue, $0400

# CHR$ codes [Programmer's Reference Guide, appendix C]
RETURN, SHIFT_RETURN, CLEAR, HOME, QUOTE, SPACE = 13, 141, 147, 19, 34, 32
CURSOR_DOWN, CURSOR_UP, CURSOR_RIGHT, CURSOR_LEFT = 17, 145, 29, 157
REVERSE_ON, REVERSE_OFF = 18, 146
COLOR_CODES = {144: 0, 5: 1, 28: 2, 159: 3, 156: 4, 30: 5, 31: 6, 158: 7, 129: 8, 149: 9, 150: 10, 151: 11, 152: 12,
               153: 13, 154: 14, 155: 15}
REVERSE_BIT = 0x80  # a screen code shown reversed

# ASCII stand-ins for the transcript of what was printed: PETSCII $20-$5F are ASCII's $20-$5F but
# for the pound sign and the two arrows
TRANSCRIPT_SPECIAL = {0x5C: "£", 0x5E: "↑", 0x5F: "←"}


def screen_code(petscii: int) -> int:
    """The screen code that shows a printable CHR$ code [Programmer's Reference Guide, appendices B, C]."""
    if petscii == 0xFF:
        return 0x5E  # pi
    if 0x20 <= petscii <= 0x3F:
        return petscii
    if 0x40 <= petscii <= 0x5F or 0xA0 <= petscii <= 0xBF:
        return petscii - 0x40
    if 0x60 <= petscii <= 0x7F:
        return petscii - 0x20
    if 0xC0 <= petscii <= 0xFE:
        return petscii - 0x80
    raise ValueError(f"CHR$({petscii}) is a control code")


def is_control(petscii: int) -> bool:
    return petscii < 0x20 or 0x80 <= petscii < 0xA0


@dataclass
class ScreenEditor:
    """The KERNAL's screen output as far as the stubs need it (module docstring); `lines` is the
    transcript of what was printed, one entry per RETURN."""

    memory: list[int]
    lines: list[str] = field(default_factory=lambda: [""])
    quote_mode: bool = False

    def reset(self) -> None:
        """The work area as after RUN: cursor home, light blue, screen at $0400."""
        self.memory[COLOR], self.memory[HIBASE] = KERNAL_COLOR, KERNAL_HIBASE
        self.memory[RVS] = 0
        self._move(0, 0)

    @property
    def row(self) -> int:
        return self.memory[TBLX]

    @property
    def column(self) -> int:
        return self.memory[PNTR]

    def _move(self, row: int, column: int) -> None:
        while column >= TEXT_COLUMNS:
            column -= TEXT_COLUMNS
            row += 1
        while column < 0:
            column += TEXT_COLUMNS
            row -= 1
        row = max(row, 0)
        if row >= TEXT_ROWS:
            self._scroll(row - TEXT_ROWS + 1)
            row = TEXT_ROWS - 1
        memory = self.memory
        screen = memory[HIBASE] << 8
        line, colours = (screen + row * TEXT_COLUMNS) & 0xFFFF, COLOR_RAM + row * TEXT_COLUMNS
        memory[TBLX], memory[PNTR] = row, column
        memory[PNT], memory[PNT + 1] = line & 0xFF, line >> 8
        memory[USER], memory[USER + 1] = colours & 0xFF, colours >> 8

    def _scroll(self, rows: int) -> None:
        memory = self.memory
        cells = TEXT_COLUMNS * TEXT_ROWS
        shift = rows * TEXT_COLUMNS
        for base, blank in ((memory[HIBASE] << 8, SPACE), (COLOR_RAM, memory[COLOR] & 0x0F)):
            for i in range(cells):  # addresses wrap at 64K, as the CPU's do
                memory[(base + i) & 0xFFFF] = memory[(base + i + shift) & 0xFFFF] if i + shift < cells else blank

    def _text(self, text: str) -> None:
        self.lines[-1] += text

    def put(self, petscii: int) -> None:
        """Print one CHR$ code at the cursor."""
        memory = self.memory
        row, column = self.row, self.column
        if petscii in (RETURN, SHIFT_RETURN):
            memory[RVS] = 0
            self.quote_mode = False
            self.lines.append("")
            self._move(row + 1, 0)
            return
        if is_control(petscii):
            self._control(petscii, row, column)
            return
        if petscii == QUOTE:
            self.quote_mode = not self.quote_mode
        code = screen_code(petscii) | (REVERSE_BIT if memory[RVS] else 0)
        offset = row * TEXT_COLUMNS + column
        memory[((memory[HIBASE] << 8) + offset) & 0xFFFF] = code
        memory[COLOR_RAM + offset] = memory[COLOR] & 0x0F
        ascii_like = petscii if 0x20 <= petscii <= 0x5F else None
        self._text(TRANSCRIPT_SPECIAL.get(petscii, chr(ascii_like) if ascii_like else f"{{${petscii:02X}}}"))
        self._move(row, column + 1)

    def _control(self, petscii: int, row: int, column: int) -> None:
        if self.quote_mode:
            raise RunError(f"the program printed CHR$({petscii}) in quote mode: retro's screen editor stub does not "
                           f"model quote mode (docs/vic.md, \"ROM stubs\")")
        memory = self.memory
        if petscii == CLEAR:
            screen = memory[HIBASE] << 8
            for i in range(TEXT_COLUMNS * TEXT_ROWS):
                memory[(screen + i) & 0xFFFF] = SPACE
            self._text("{clr}")
            self._move(0, 0)
        elif petscii == HOME:
            self._move(0, 0)
        elif petscii in (CURSOR_DOWN, CURSOR_UP):
            self._move(row + (1 if petscii == CURSOR_DOWN else -1), column)
        elif petscii in (CURSOR_RIGHT, CURSOR_LEFT):
            self._move(row, column + (1 if petscii == CURSOR_RIGHT else -1))
        elif petscii in (REVERSE_ON, REVERSE_OFF):
            memory[RVS] = 1 if petscii == REVERSE_ON else 0
        elif petscii in COLOR_CODES:
            memory[COLOR] = COLOR_CODES[petscii]
        else:
            raise RunError(f"the program printed CHR$({petscii}), a control code retro's screen editor stub does not "
                           f"model (docs/vic.md, \"ROM stubs\")")

    @property
    def transcript(self) -> list[str]:
        """What was printed, one line per RETURN (without a last empty line)."""
        return self.lines[:-1] if self.lines[-1] == "" else list(self.lines)


def _return(mpu) -> int:
    """End a stub as its RTS would: pull the return address; the stub's cycles."""
    mpu.pc = (mpu.stPopWord() + 1) & 0xFFFF
    return STUB_CYCLES


@dataclass
class C64Stubs:
    """What a program run's stubs left: the screen editor (its transcript) and CIA 1."""

    editor: ScreenEditor
    cia1: Cia1Timers
    bank_port: object

    def strout(self, mpu) -> int:
        memory = self.editor.memory
        at = mpu.a | mpu.y << 8
        for i in range(STRING_LIMIT + 1):
            petscii = memory[(at + i) & 0xFFFF]
            if petscii in (0, QUOTE):
                return _return(mpu)
            self.editor.put(petscii)
        raise RunError(f"STROUT ($AB1E) of the text at ${at:04X}: no 0 or quote ends it within {STRING_LIMIT} bytes")

    def linprt(self, mpu) -> int:
        for char in f" {mpu.a << 8 | mpu.x}":
            self.editor.put(ord(char))
        return _return(mpu)

    def ioinit(self, mpu) -> int:
        cycle = mpu.processorCycles
        self.cia1.write(CIA1_BASE + REG_ICR, ICR_SOURCES, cycle)  # bit 7 clear: every source masked
        for register in (REG_CRA, REG_CRB):
            self.cia1.write(CIA1_BASE + register, CR_AFTER_IOINIT, cycle)
        self.bank_port.set_bank(0)
        return _return(mpu)

    def actions(self) -> dict[int, Callable]:
        return {STROUT: self.strout, LINPRT: self.linprt, IOINIT: self.ioinit}


def install_c64_stubs(machine: Machine, bank_port) -> C64Stubs:
    """Attach CIA 1's timers at $DC00-$DCFF and put the ROM routine stubs (module docstring) at their
    addresses, the screen editor's work area as after RUN. `bank_port`: CIA 2's port (IOINIT resets it)."""
    cia1 = machine.attach(Cia1Timers(lambda: machine.cycle), CIA1_BASE, CIA1_LAST)
    editor = ScreenEditor(machine.bus.memory)
    editor.reset()
    stubs = C64Stubs(editor, cia1, bank_port)
    actions = stubs.actions()
    install_on_mpu(machine.mpu, actions)
    for address in actions:
        machine.bus.memory[address] = TRAP_OPCODE
        machine.trap_names[address] = f"{ROM_STUB_NAMES[address]} (stub)"
    return stubs

