"""One instruction's text from its bytes: the one disassembler of retro (the run and check traces,
the budget error's last instructions and the coverage listings all write instructions this way).

`instruction_text(mnemonic, mode, address, lo, hi)` is the operand syntax; `decode_at(read, address,
cpu)` reads an instruction from any memory (a program's bytes, a machine's memory) with the opcode
table of that CPU (`retro.cpu.opcodes`: the NMOS table for the 6510 and the 2A03, the WDC table for
the 65C02)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from retro.cpu.opcodes import MODE_LENGTH, OPCODE_TABLE, OPCODE_TABLE_65C02, Op
from retro.cpu.timing import WDC_65C02

SHIFTS = ("ASL", "LSR", "ROL", "ROR")  # accumulator mode is written `ASL A`
BRANCH_MODES = ("rel", "zpr")  # a relative offset: Bxx, and the 65C02's BBR/BBS (zero page, then offset)


def _relative(address: int, length: int, offset: int) -> int:
    return (address + length + (offset - 256 if offset & 0x80 else offset)) & 0xFFFF


def instruction_text(mnemonic: str, mode: str, address: int, lo: int, hi: int) -> str:
    """`LDA $C000,X`, `BNE $C010` (the target, not the offset), `ASL A`, `BBR0 $12,$C020`."""
    word = lo | hi << 8
    operand = {
        "imp": "", "acc": "A" if mnemonic in SHIFTS else "", "imm": f"#${lo:02X}",
        "zpg": f"${lo:02X}", "zpx": f"${lo:02X},X", "zpy": f"${lo:02X},Y",
        "abs": f"${word:04X}", "abx": f"${word:04X},X", "aby": f"${word:04X},Y",
        "ind": f"(${word:04X})", "inx": f"(${lo:02X},X)", "iny": f"(${lo:02X}),Y",
        "rel": f"${_relative(address, 2, lo):04X}",
        "zpi": f"(${lo:02X})", "iax": f"(${word:04X},X)",  # the 65C02's
        "zpr": f"${lo:02X},${_relative(address, 3, hi):04X}",
    }.get(mode, "")
    return f"{mnemonic} {operand}".strip()


@dataclass(frozen=True)
class Instruction:
    address: int
    data: bytes  # the opcode and its operand bytes
    mnemonic: str
    mode: str
    text: str  # `LDA $C000,X`

    @property
    def length(self) -> int:
        return len(self.data)

    @property
    def is_branch(self) -> bool:
        """A conditional branch (two ways out); the 65C02's BRA always goes one way."""
        return self.mode in BRANCH_MODES and self.mnemonic != "BRA"

    @property
    def target(self) -> int | None:
        """Where a branch, JMP absolute or JSR goes (None for the others)."""
        if self.mode == "rel":
            return _relative(self.address, 2, self.data[1])
        if self.mode == "zpr":
            return _relative(self.address, 3, self.data[2])
        if self.mnemonic in ("JMP", "JSR") and self.mode == "abs":
            return self.data[1] | self.data[2] << 8
        return None


def opcode_table(cpu: str) -> dict[int, Op]:
    return OPCODE_TABLE_65C02 if cpu == WDC_65C02 else OPCODE_TABLE


def decode_at(read: Callable[[int], int], address: int, cpu: str = "6510") -> Instruction:
    """The instruction at `address` (`read(address) -> byte`; addresses wrap at $FFFF)."""
    op = opcode_table(cpu)[read(address)]
    data = bytes(read((address + i) & 0xFFFF) for i in range(MODE_LENGTH[op.mode]))
    lo = data[1] if len(data) > 1 else 0
    hi = data[2] if len(data) > 2 else 0
    return Instruction(address, data, op.mnemonic, op.mode,
                       instruction_text(op.mnemonic, op.mode, address, lo, hi))
