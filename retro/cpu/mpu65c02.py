"""The WDC 65C02 core: `MPU65C02`, built on the NMOS core (retro.cpu.mpu) from its opcode table
(retro.cpu.opcodes.OPCODE_TABLE_65C02); docs/cpu.md."""

from __future__ import annotations

from py65.utils.devices import make_instruction_decorator

from retro.cpu.mpu import (
    _KEEP_ALL_BUT_NVZC,
    ADDRESS_MASK,
    FLAG_C,
    FLAG_D,
    FLAG_N,
    FLAG_V,
    FLAG_Z,
    PAGE_SHIFT,
    MPU6510,
    _copy_tables,
    _py65_brk,
)
from retro.cpu.opcodes import DECIMAL_EXTRA_CYCLES, MODE_LENGTH, OPCODE_TABLE, OPCODE_TABLE_65C02, RESERVED


class MPU65C02(MPU6510):
    """The WDC 65C02 (W65C02S): the CMOS 6502 of the Commander X16, Foenix F256 and enhanced Apple II.

    Built on MPU6510 (the same bus, run loop and documented NMOS handlers, which the 65C02 shares)
    with every row of `OPCODE_TABLE_65C02` that differs put in from that table: the new opcodes and
    modes, the reserved opcodes as NOPs, the fixed JMP (abs), and cycles and page penalties of every
    opcode from the table. py65 1.2.0's own MPU65C02 is not used: it lacks BBR/BBS, STP, the reserved
    opcodes' sizes and cycles, the decimal-mode flags and extra cycle, and keeps NMOS RMW timing.
    Decimal mode (Bruce Clark, "Decimal Mode", appendix A, the 65C02): ADC gives A and C by sequence 1,
    V by sequence 2, N and Z from the result; SBC gives A by sequence 4, C and V from the binary
    difference, N and Z from the result; both take one cycle more with D set. BRK and interrupts clear D.
    STP stops the clock until a reset, WAI until an interrupt: no chip drives a 65C02's interrupt lines
    here, so both stop the run with CpuHalt naming them. (For the same reason `step_timed`'s stall
    model, which knows the NMOS write cycles, is not adapted to the 65C02's.)
    Read-modify-writes (ASL ... INC DEC, TSB TRB, RMB SMB) write the result once, in their last cycle
    (the 65C02 reads the operand twice where the NMOS writes it twice).
    """

    instruct, cycletime, extracycles, disassemble = _copy_tables(MPU6510)
    instruction = make_instruction_decorator(instruct, disassemble, cycletime, extracycles)
    opcode_table = OPCODE_TABLE_65C02
    interrupt_clears = FLAG_D
    decimal_extra_cycles = DECIMAL_EXTRA_CYCLES

    def ZeroPageIndirectAddr(self):
        pointer = self.memory[self.pc]
        return self.ByteAt(pointer) | self.ByteAt((pointer + 1) & 0xFF) << 8

    def _write_back(self, addr: int, old: int, new: int) -> None:
        device = self.page_devices[addr >> PAGE_SHIFT]
        if device is None:
            self.memory[addr] = new
        else:
            device.write(addr, new, self._access_cycle(1))

    def _adc(self, v: int) -> None:
        if not self.p & FLAG_D:
            MPU6510._adc(self, v)
            return
        self.excycles += self.decimal_extra_cycles
        a = self.a
        carry = self.p & FLAG_C
        low = (a & 0x0F) + (v & 0x0F) + carry  # Clark, sequence 1
        if low >= 0x0A:
            low = ((low + 0x06) & 0x0F) + 0x10
        total = (a & 0xF0) + (v & 0xF0) + low
        signed = _signed_high(a) + _signed_high(v) + low  # sequence 2: V
        if total >= 0xA0:
            total += 0x60
        result = total & 0xFF
        self.p = (self.p & _KEEP_ALL_BUT_NVZC) | (result & FLAG_N) | (0 if result else FLAG_Z) \
            | (FLAG_V if not -128 <= signed <= 127 else 0) | (FLAG_C if total > 0xFF else 0)
        self.a = result

    def _sbc(self, v: int) -> None:
        if not self.p & FLAG_D:
            MPU6510._sbc(self, v)
            return
        self.excycles += self.decimal_extra_cycles
        a = self.a
        borrow = 1 - (self.p & FLAG_C)
        MPU6510._sbc(self, v)  # C and V from the binary difference (A is set below)
        low = (a & 0x0F) - (v & 0x0F) - borrow  # Clark, sequence 4
        total = a - v - borrow
        if total < 0:
            total -= 0x60
        if low < 0:
            total -= 0x06
        result = total & 0xFF
        self.p = (self.p & ~(FLAG_N | FLAG_Z)) | (result & FLAG_N) | (0 if result else FLAG_Z)
        self.a = result


def _signed_high(value: int) -> int:
    high = value & 0xF0
    return high - 0x100 if high & 0x80 else high


_C02_MODES = {"zpg": "ZeroPageAddr", "zpx": "ZeroPageXAddr", "abs": "AbsoluteAddr", "abx": "AbsoluteXAddr",
              "zpi": "ZeroPageIndirectAddr", "imm": "ProgramCounter"}  # py65's addressing helpers by mode
_C02_ALU = {"ORA": "opORA", "AND": "opAND", "EOR": "opEOR", "ADC": "opADC", "SBC": "opSBC", "LDA": "opLDA",
            "STA": "opSTA", "BIT": "opBIT"}  # NMOS operations the 65C02 also has in new modes


def _address(s, mode: str) -> int:
    return getattr(s, _C02_MODES[mode])()


def _bit_immediate(s) -> None:  # BIT #imm sets only Z
    s.p = (s.p & ~FLAG_Z) | (0 if s.a & s.memory[s.pc] else FLAG_Z)


def _test_and(s, mode: str, setting: bool) -> None:  # TSB / TRB: Z from A AND M, then set or clear A's bits in M
    addr = _address(s, mode)
    value = s.ByteAt(addr)
    s.p = (s.p & ~FLAG_Z) | (0 if s.a & value else FLAG_Z)
    s._write_back(addr, value, (value | s.a) if setting else (value & ~s.a & 0xFF))


def _memory_bit(s, mask: int, setting: bool) -> None:  # RMB / SMB
    addr = s.memory[s.pc]
    value = s.ByteAt(addr)
    s._write_back(addr, value, (value | mask) if setting else (value & ~mask & 0xFF))


def _bit_branch(s, mask: int, when_set: bool) -> None:  # BBR / BBS: test a zero-page bit, then branch relative
    value = s.ByteAt(s.memory[s.pc])
    if bool(value & mask) == when_set:
        s.pc = (s.pc + 1) & ADDRESS_MASK
        s.BranchRelAddr()  # +1 taken, +1 more into another page; leaves PC at the target
        s.pc -= 2  # the handler's length step (3 - 1) follows


def _jmp_indirect(s) -> int:  # the 65C02 reads the pointer's high byte across a page correctly
    pointer = s.AbsoluteAddr()
    return s.ByteAt(pointer) | s.ByteAt((pointer + 1) & ADDRESS_MASK) << 8


def _jmp_indexed_indirect(s) -> int:
    pointer = (s.AbsoluteAddr() + s.x) & ADDRESS_MASK
    return s.ByteAt(pointer) | s.ByteAt((pointer + 1) & ADDRESS_MASK) << 8


def _halting(reason: str):
    return lambda s: s.halt_on(reason)


# The 65C02's new operations by mnemonic (RMB/SMB/BBR/BBS by their first three letters, the bit number
# being the fourth): each makes the body of the handler for one (mnemonic, mode).
_C02_OPERATIONS = {
    "BRA": lambda name, mode: lambda s: (s.BranchRelAddr(), setattr(s, "pc", s.pc - 1)),
    "CMP": lambda name, mode: lambda s: s.opCMPR(getattr(s, _C02_MODES[mode]), s.a),
    "STZ": lambda name, mode: lambda s: s.WriteByte(_address(s, mode), 0),
    "TSB": lambda name, mode: lambda s: _test_and(s, mode, True),
    "TRB": lambda name, mode: lambda s: _test_and(s, mode, False),
    "INC": lambda name, mode: lambda s: setattr(s, "a", s._nz((s.a + 1) & 0xFF)),  # INC A
    "DEC": lambda name, mode: lambda s: setattr(s, "a", s._nz((s.a - 1) & 0xFF)),  # DEC A
    "PHX": lambda name, mode: lambda s: s.stPush(s.x),
    "PHY": lambda name, mode: lambda s: s.stPush(s.y),
    "PLX": lambda name, mode: lambda s: setattr(s, "x", s._nz(s.stPop())),
    "PLY": lambda name, mode: lambda s: setattr(s, "y", s._nz(s.stPop())),
    "RMB": lambda name, mode: lambda s: _memory_bit(s, 1 << int(name[3]), False),
    "SMB": lambda name, mode: lambda s: _memory_bit(s, 1 << int(name[3]), True),
    "BBR": lambda name, mode: lambda s: _bit_branch(s, 1 << int(name[3]), False),
    "BBS": lambda name, mode: lambda s: _bit_branch(s, 1 << int(name[3]), True),
    "WAI": lambda name, mode: _halting("WAI with no interrupt source"),
    "STP": lambda name, mode: _halting("STP"),
    "BRK": lambda name, mode: _brk_65c02,
}


def _c02_operation(name: str, mode: str):
    if name == "BIT" and mode == "imm":
        return _bit_immediate
    if name in _C02_ALU:
        return lambda s: getattr(s, _C02_ALU[name])(getattr(s, _C02_MODES[mode]))
    make = _C02_OPERATIONS.get(name[:3] if name[:3] in ("RMB", "SMB", "BBR", "BBS") else name)
    if make is None:  # pragma: no cover - a new table row needs its operation here
        raise AssertionError(f"no 65C02 operation for {name} ({mode})")
    return make(name, mode)


def _install(cls, opcode: int, row, body) -> None:
    """A handler running `body`, then stepping the PC past the operand, as py65's handlers do."""
    length = MODE_LENGTH[row.mode]

    def handler(self):
        body(self)
        self.pc += length - 1
    handler.__name__ = f"inst_0x{opcode:02x}"
    cls.instruction(name=row.mnemonic, mode=row.mode, cycles=row.cycles, extracycles=int(row.page_penalty))(handler)


def _install_jump(cls, opcode: int, row, target) -> None:
    def handler(self):
        self.pc = target(self)
    handler.__name__ = f"inst_0x{opcode:02x}"
    cls.instruction(name=row.mnemonic, mode=row.mode, cycles=row.cycles, extracycles=0)(handler)


def _register_65c02(cls) -> None:
    """Put into cls's tables every 65C02 row that the NMOS documented handlers do not already run."""
    for opcode, row in cls.opcode_table.items():
        nmos = OPCODE_TABLE[opcode]
        if row.kind == RESERVED:
            _install(cls, opcode, row, lambda s: None)
        elif (nmos.mnemonic, nmos.mode, nmos.kind) == (row.mnemonic, row.mode, row.kind) and opcode not in (0x00, 0x6C):
            continue  # the NMOS handler does the same (cycles are set from the table below)
        elif row.mnemonic == "JMP":
            _install_jump(cls, opcode, row, _jmp_indirect if row.mode == "ind" else _jmp_indexed_indirect)
        else:
            _install(cls, opcode, row, _c02_operation(row.mnemonic, row.mode))
    for opcode, row in cls.opcode_table.items():  # every opcode's cycles and page penalty, from the table
        cls.cycletime[opcode] = row.cycles
        cls.extracycles[opcode] = int(row.page_penalty)
        cls.disassemble[opcode] = (row.mnemonic, row.mode)
    cls.RMW_OPCODES = frozenset(opcode for opcode, row in cls.opcode_table.items() if row.mode != "acc" and (
        row.mnemonic in ("ASL", "LSR", "ROL", "ROR", "INC", "DEC", "TSB", "TRB") or row.mnemonic[:3] in ("RMB", "SMB")))


def _brk_65c02(self):
    if self.stop_on_brk:
        self.halt_on("BRK")
    _py65_brk(self)
    self.p &= ~FLAG_D


_register_65c02(MPU65C02)
