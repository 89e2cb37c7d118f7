"""A deliberately simple WDC 65C02 reference stepper, used only by the tests as a second, independent core.

It shares nothing with retro.cpu (no opcode table, no py65): instructions are decoded from the bit
fields of the opcode (aaabbbcc, the way the 6502 family lays its opcode matrix out), and cycles come
from rules per addressing mode and kind of operation, as WDC's "W65C02S 8-bit Microprocessor" data
sheet states them (table 5-7 and its notes):

- reads: #imm 2, zp 3, zp,X/zp,Y 4, abs 4, abs,X/abs,Y 4 (+1 across a page), (zp,X) 6, (zp),Y 5
  (+1 across a page), (zp) 5; ADC/SBC +1 with D set;
- writes: zp 3, zp,X 4, abs 4, abs,X/abs,Y 5, (zp,X) 6, (zp),Y 6, (zp) 5;
- read-modify-writes: A 2, zp 5, zp,X 6, abs 6, abs,X 7 for INC/DEC and 6 (+1 across a page) for
  the shifts and rotates; TSB/TRB zp 5, abs 6; RMB/SMB 5;
- branches 2, +1 taken, +1 more into another page; BRA 3 (+1); BBR/BBS 5 (+1 taken, +1 page);
- JMP abs 3, JMP (abs) 6 and JMP (abs,X) 6; JSR, RTS, RTI 6; BRK 7; pushes 3, pulls 4; others 2;
  WAI and STP 3 (they stop this stepper: `halted`);
- the reserved opcodes are NOPs: x3 and xB one byte, one cycle; x2 two bytes, two cycles; $44 two
  bytes, 3 cycles; $54 $D4 $F4 two bytes, 4; $DC $FC three bytes, 4; $5C three bytes, 8.

Decimal mode as the 65C02 computes it (Bruce Clark, "Decimal Mode", appendix A), written nybble by
nybble: ADC adjusts each nybble past 9 by 6, C from the high nybble, V from the signed high nybbles;
SBC subtracts in binary, then takes 6 from the result when the low nybble borrowed and $60 when the
byte did; N and Z from the result in both.
"""

from __future__ import annotations

N, V, U, B, D, I, Z, C = 0x80, 0x40, 0x20, 0x10, 0x08, 0x04, 0x02, 0x01


class Ref65C02:
    def __init__(self, memory: bytearray, pc: int, a: int, x: int, y: int, s: int, p: int) -> None:
        self.m = memory
        self.pc, self.a, self.x, self.y, self.s, self.p = pc, a, x, y, s, p
        self.cycles = 0
        self.halted = False

    # ---- helpers ----
    def byte(self, offset: int) -> int:
        return self.m[(self.pc + offset) & 0xFFFF]

    def word_at(self, address: int) -> int:
        return self.m[address & 0xFFFF] | self.m[(address + 1) & 0xFFFF] << 8

    def zp_word(self, zp: int) -> int:
        return self.m[zp & 0xFF] | self.m[(zp + 1) & 0xFF] << 8

    def flag(self, bit: int, on) -> None:
        self.p = (self.p | bit) if on else (self.p & ~bit & 0xFF)

    def setnz(self, value: int) -> int:
        self.flag(N, value & 0x80)
        self.flag(Z, value == 0)
        return value

    def push(self, value: int) -> None:
        self.m[0x100 + self.s] = value & 0xFF
        self.s = (self.s - 1) & 0xFF

    def pull(self) -> int:
        self.s = (self.s + 1) & 0xFF
        return self.m[0x100 + self.s]

    # ---- operand addresses: (address, length, page crossed) ----
    def operand(self, mode: str):
        lo, hi = self.byte(1), self.byte(2)
        if mode == "zp":
            return lo, 2, False
        if mode == "zpx":
            return (lo + self.x) & 0xFF, 2, False
        if mode == "zpy":
            return (lo + self.y) & 0xFF, 2, False
        if mode == "abs":
            return lo | hi << 8, 3, False
        if mode in ("absx", "absy"):
            base = lo | hi << 8
            address = (base + (self.x if mode == "absx" else self.y)) & 0xFFFF
            return address, 3, (base >> 8) != (address >> 8)
        if mode == "izx":
            return self.zp_word(lo + self.x), 2, False
        if mode == "izy":
            base = self.zp_word(lo)
            address = (base + self.y) & 0xFFFF
            return address, 2, (base >> 8) != (address >> 8)
        if mode == "izp":
            return self.zp_word(lo), 2, False
        raise AssertionError(mode)

    READ_CYCLES = {"imm": 2, "zp": 3, "zpx": 4, "zpy": 4, "abs": 4, "absx": 4, "absy": 4, "izx": 6, "izy": 5,
                   "izp": 5}
    WRITE_CYCLES = {"zp": 3, "zpx": 4, "zpy": 4, "abs": 4, "absx": 5, "absy": 5, "izx": 6, "izy": 6, "izp": 5}

    # ---- arithmetic ----
    def adc(self, value: int) -> None:
        a, carry = self.a, self.p & C
        if not self.p & D:
            total = a + value + carry
            self.flag(V, ~(a ^ value) & (a ^ total) & 0x80)
            self.flag(C, total > 0xFF)
            self.a = self.setnz(total & 0xFF)
            return
        self.cycles += 1
        low = (a & 0x0F) + (value & 0x0F) + carry
        half = 0
        if low > 9:
            low += 6
        if low > 0x0F:
            half = 1
        low &= 0x0F
        high = (a >> 4) + (value >> 4) + half
        signed_high = (a >> 4) - (16 if a & 0x80 else 0) + (value >> 4) - (16 if value & 0x80 else 0) + half
        self.flag(V, not -8 <= signed_high <= 7)
        if high > 9:
            high += 6
        self.flag(C, high > 0x0F)
        self.a = self.setnz((high << 4 | low) & 0xFF)

    def sbc(self, value: int) -> None:
        a, borrow = self.a, 1 - (self.p & C)
        difference = a - value - borrow
        self.flag(V, (a ^ value) & (a ^ difference) & 0x80)
        self.flag(C, difference >= 0)
        if self.p & D:
            self.cycles += 1
            if difference < 0:
                difference -= 0x60
            if (a & 0x0F) - (value & 0x0F) - borrow < 0:
                difference -= 0x06
        self.a = self.setnz(difference & 0xFF)

    def compare(self, register: int, value: int) -> None:
        self.flag(C, register >= value)
        self.setnz((register - value) & 0xFF)

    def shift(self, kind: int, value: int) -> int:  # kind: aaa of the cc=10 group (0 ASL 1 ROL 2 LSR 3 ROR)
        carry_in = self.p & C
        if kind in (0, 1):
            self.flag(C, value & 0x80)
            result = (value << 1 | (carry_in if kind == 1 else 0)) & 0xFF
        else:
            self.flag(C, value & 1)
            result = value >> 1 | (carry_in << 7 if kind == 3 else 0)
        return self.setnz(result)

    def branch(self, taken: bool, offset: int, length: int) -> None:
        following = (self.pc + length) & 0xFFFF
        if taken:
            target = (following + (offset - 256 if offset & 0x80 else offset)) & 0xFFFF
            self.cycles += 1 + ((target >> 8) != (following >> 8))
            self.pc = target
        else:
            self.pc = following

    # ---- one instruction ----
    def step(self) -> None:
        op = self.m[self.pc]
        aaa, bbb, cc = op >> 5, (op >> 2) & 7, op & 3
        low = op & 0x0F
        if low in (0x03, 0x0B) and op not in (0xCB, 0xDB):
            self.cycles += 1
            self.pc = (self.pc + 1) & 0xFFFF
            return
        special = self.special(op)
        if special:
            return
        if low == 0x07:  # RMB / SMB
            zp = self.byte(1)
            mask = 1 << ((op >> 4) & 7)
            self.m[zp] = (self.m[zp] | mask) if op & 0x80 else (self.m[zp] & ~mask & 0xFF)
            self.cycles += 5
            self.pc = (self.pc + 2) & 0xFFFF
            return
        if low == 0x0F:  # BBR / BBS
            value = self.m[self.byte(1)]
            bit = value >> ((op >> 4) & 7) & 1
            self.cycles += 5
            self.branch(bit == (op >> 7), self.byte(2), 3)
            return
        if cc == 1 or (cc == 2 and bbb == 4):  # the ALU group; cc=2, bbb=4: the (zp) column
            mode = "izp" if cc == 2 else ("izx", "zp", "imm", "abs", "izy", "zpx", "absy", "absx")[bbb]
            self.alu(aaa, mode)
            return
        if cc == 2:
            self.group_two(op, aaa, bbb)
            return
        self.group_zero(op, aaa, bbb)

    def alu(self, aaa: int, mode: str) -> None:
        if aaa == 4:  # STA
            address, length, _ = self.operand(mode)
            self.m[address] = self.a
            self.cycles += self.WRITE_CYCLES[mode]
            self.pc = (self.pc + length) & 0xFFFF
            return
        if mode == "imm":
            value, length, crossed = self.byte(1), 2, False
        else:
            address, length, crossed = self.operand(mode)
            value = self.m[address]
        self.cycles += self.READ_CYCLES[mode] + (crossed and mode in ("absx", "absy", "izy"))
        if aaa == 0:
            self.a = self.setnz(self.a | value)
        elif aaa == 1:
            self.a = self.setnz(self.a & value)
        elif aaa == 2:
            self.a = self.setnz(self.a ^ value)
        elif aaa == 3:
            self.adc(value)
        elif aaa == 5:
            self.a = self.setnz(value)
        elif aaa == 6:
            self.compare(self.a, value)
        else:
            self.sbc(value)
        self.pc = (self.pc + length) & 0xFFFF

    def group_two(self, op: int, aaa: int, bbb: int) -> None:
        if bbb == 0:  # column x2: LDX #imm, else a two-byte NOP
            if aaa == 5:
                self.x = self.setnz(self.byte(1))
            self.cycles += 2
            self.pc = (self.pc + 2) & 0xFFFF
            return
        if bbb == 2 and aaa < 4:  # shifts on A
            self.a = self.shift(aaa, self.a)
            self.cycles += 2
            self.pc = (self.pc + 1) & 0xFFFF
            return
        index_y = aaa in (4, 5)  # STX/LDX index with Y
        mode = {1: "zp", 3: "abs", 5: "zpy" if index_y else "zpx", 7: "absy" if index_y else "absx"}[bbb]
        address, length, crossed = self.operand(mode)
        if aaa == 4:  # STX
            self.m[address] = self.x
            self.cycles += self.WRITE_CYCLES[mode]
        elif aaa == 5:  # LDX
            self.x = self.setnz(self.m[address])
            self.cycles += self.READ_CYCLES[mode] + (crossed and mode == "absy")
        else:  # ASL ROL LSR ROR DEC INC on memory
            value = self.m[address]
            if aaa == 6:
                result = self.setnz((value - 1) & 0xFF)
            elif aaa == 7:
                result = self.setnz((value + 1) & 0xFF)
            else:
                result = self.shift(aaa, value)
            self.m[address] = result
            self.cycles += {"zp": 5, "zpx": 6, "abs": 6}.get(mode) or (7 if aaa >= 6 else 6 + crossed)
        self.pc = (self.pc + length) & 0xFFFF

    def group_zero(self, op: int, aaa: int, bbb: int) -> None:
        if bbb == 0:  # #imm: LDY CPY CPX (the others in column x0 are special)
            value = self.byte(1)
            if aaa == 5:
                self.y = self.setnz(value)
            else:
                self.compare(self.y if aaa == 6 else self.x, value)
            self.cycles += 2
            self.pc = (self.pc + 2) & 0xFFFF
            return
        mode = {1: "zp", 3: "abs", 5: "zpx", 7: "absx"}[bbb]
        address, length, crossed = self.operand(mode)
        if aaa == 4:  # STY
            self.m[address] = self.y
            self.cycles += self.WRITE_CYCLES[mode]
        else:
            value = self.m[address]
            self.cycles += self.READ_CYCLES[mode] + (crossed and mode == "absx")
            if aaa == 1:  # BIT
                self.flag(N, value & 0x80)
                self.flag(V, value & 0x40)
                self.flag(Z, (self.a & value) == 0)
            elif aaa == 5:
                self.y = self.setnz(value)
            else:
                self.compare(self.y if aaa == 6 else self.x, value)
        self.pc = (self.pc + length) & 0xFFFF

    def special(self, op: int) -> bool:
        """The opcodes outside the regular groups; True when op was one of them."""
        pc = self.pc
        one = (pc + 1) & 0xFFFF

        def done(cycles: int, length: int = 1) -> bool:
            self.cycles += cycles
            self.pc = (pc + length) & 0xFFFF
            return True
        if (op & 0x1F) == 0x10:  # conditional branches: flag by aaa >> 1, wanted value aaa & 1
            flag = (N, V, C, Z)[op >> 6]
            self.cycles += 2
            self.branch(bool(self.p & flag) == bool(op & 0x20), self.byte(1), 2)
            return True
        if op == 0x80:  # BRA
            self.cycles += 2
            self.branch(True, self.byte(1), 2)
            return True
        if op == 0x00:  # BRK: pushes PC+2 and P with B, sets I, clears D
            back = (pc + 2) & 0xFFFF
            self.push(back >> 8)
            self.push(back)
            self.push(self.p | B | U)
            self.p = (self.p | I) & ~D & 0xFF
            self.pc = self.word_at(0xFFFE)
            self.cycles += 7
            return True
        if op == 0x20:  # JSR
            back = (pc + 2) & 0xFFFF
            self.push(back >> 8)
            self.push(back)
            self.pc = self.byte(1) | self.byte(2) << 8
            self.cycles += 6
            return True
        if op == 0x40:  # RTI
            self.p = (self.pull() | U) & ~B & 0xFF
            low = self.pull()
            self.pc = low | self.pull() << 8
            self.cycles += 6
            return True
        if op == 0x60:  # RTS
            low = self.pull()
            self.pc = ((low | self.pull() << 8) + 1) & 0xFFFF
            self.cycles += 6
            return True
        if op in (0x4C, 0x6C, 0x7C):  # JMP abs, (abs), (abs,X)
            target = self.byte(1) | self.byte(2) << 8
            if op == 0x6C:
                target = self.word_at(target)
            elif op == 0x7C:
                target = self.word_at(target + self.x)
            self.pc = target
            self.cycles += 3 if op == 0x4C else 6
            return True
        if op in (0xCB, 0xDB):  # WAI, STP
            self.halted = True
            self.cycles += 3
            return True
        pushes = {0x08: lambda: self.p | B | U, 0x48: lambda: self.a, 0x5A: lambda: self.y, 0xDA: lambda: self.x}
        if op in pushes:
            self.push(pushes[op]())
            return done(3)
        if op == 0x28:
            self.p = (self.pull() | U) & ~B & 0xFF
            return done(4)
        pulls = {0x68: "a", 0x7A: "y", 0xFA: "x"}
        if op in pulls:
            setattr(self, pulls[op], self.setnz(self.pull()))
            return done(4)
        flags = {0x18: (C, 0), 0x38: (C, 1), 0x58: (I, 0), 0x78: (I, 1), 0xB8: (V, 0), 0xD8: (D, 0), 0xF8: (D, 1)}
        if op in flags:
            bit, on = flags[op]
            self.flag(bit, on)
            return done(2)
        registers = {0xAA: ("a", "x"), 0xA8: ("a", "y"), 0x8A: ("x", "a"), 0x98: ("y", "a"), 0xBA: ("s", "x")}
        if op in registers:
            source, target = registers[op]
            setattr(self, target, self.setnz(getattr(self, source)))
            return done(2)
        if op == 0x9A:  # TXS
            self.s = self.x
            return done(2)
        steps = {0xE8: ("x", 1), 0xC8: ("y", 1), 0xCA: ("x", -1), 0x88: ("y", -1), 0x1A: ("a", 1), 0x3A: ("a", -1)}
        if op in steps:
            register, step = steps[op]
            setattr(self, register, self.setnz((getattr(self, register) + step) & 0xFF))
            return done(2)
        if op == 0xEA:
            return done(2)
        if op == 0x89:  # BIT #imm: Z only
            self.flag(Z, (self.a & self.byte(1)) == 0)
            return done(2, 2)
        if op in (0x04, 0x0C, 0x14, 0x1C):  # TSB / TRB zp, abs
            absolute = bool(op & 0x08)
            address = self.byte(1) | self.byte(2) << 8 if absolute else self.byte(1)
            value = self.m[address]
            self.flag(Z, (self.a & value) == 0)
            self.m[address] = (value | self.a) if op < 0x10 else (value & ~self.a & 0xFF)
            return done(6 if absolute else 5, 3 if absolute else 2)
        stz = {0x64: "zp", 0x74: "zpx", 0x9C: "abs", 0x9E: "absx"}
        if op in stz:
            address, length, _ = self.operand(stz[op])
            self.m[address] = 0
            return done(self.WRITE_CYCLES[stz[op]], length)
        if op in (0x34, 0x3C):  # BIT zp,X / abs,X
            address, length, crossed = self.operand("zpx" if op == 0x34 else "absx")
            value = self.m[address]
            self.flag(N, value & 0x80)
            self.flag(V, value & 0x40)
            self.flag(Z, (self.a & value) == 0)
            return done(4 + (crossed and op == 0x3C), length)
        nops = {0x44: (3, 2), 0x54: (4, 2), 0xD4: (4, 2), 0xF4: (4, 2), 0x5C: (8, 3), 0xDC: (4, 3), 0xFC: (4, 3)}
        if op in nops:
            cycles, length = nops[op]
            return done(cycles, length)
        return False
