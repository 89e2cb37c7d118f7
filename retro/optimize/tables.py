"""Tables as a resource: `[memory]` blocks of the spec that the user lets a candidate read
(`retro optimize --tables NAME,...`), a multiply or square table, say. The search's pool gains
every indexed read of each table (LDA, LDX, LDY, ADC, SBC, AND, ORA, EOR, CMP with X or Y), and a
routine's size counts the bytes of every allowed table its code addresses: a lookup wins on bytes
only when it is worth its table."""

from __future__ import annotations

from dataclasses import dataclass

from retro.errors import InputError
from retro.optimize.code import Instruction, Listing, opcode_of
from retro.routines.spec import Routine

READS = ("LDA", "LDX", "LDY", "ADC", "SBC", "AND", "ORA", "EOR", "CMP")
INDEXED = {"X": ("zpx", "abx"), "Y": ("zpy", "aby")}  # (zero page, absolute) mode of each index


@dataclass(frozen=True)
class Table:
    name: str
    address: int
    size: int

    def holds(self, address: int) -> bool:
        return self.address <= address < self.address + self.size


def allowed_tables(routine: Routine, names: tuple[str, ...], contents: dict) -> tuple[Table, ...]:
    """The `[memory]` blocks named, as tables (`contents`: block name -> its bytes as loaded, which
    a generator's block only has once made); an unknown name is one line naming the blocks there are."""
    blocks = {block.name: block for block in routine.memory}
    tables = []
    for name in names:
        block = blocks.get(name)
        if block is None:
            known = ", ".join(sorted(blocks)) or "none"
            raise InputError(f"--tables: {name!r} is not a [memory] block of {routine.shown_path or routine.spec_path} "
                             f"(its blocks: {known})")
        tables.append(Table(name, block.address, len(contents[name])))
    return tuple(tables)


def table_pool(cpu: str, tables: tuple[Table, ...]) -> list[Instruction]:
    """Every indexed read of every table the CPU has an opcode for (zero-page modes for a table in
    page zero, whose index wraps there as the 6502's does)."""
    forms = opcode_of(cpu)
    pool = []
    for table in tables:
        for index, (zero_page, absolute) in INDEXED.items():
            mode = zero_page if table.address < 0x100 else absolute
            for name in READS:
                if (name, mode) in forms:
                    pool.append(Instruction(name, mode, table.address))
                elif mode == zero_page and (name, absolute) in forms:  # LDX zp,Y exists; LDA zp,Y does not
                    pool.append(Instruction(name, absolute, table.address))
    return pool


def table_bytes(listing: Listing, tables: tuple[Table, ...]) -> int:
    """The bytes of the allowed tables the listing's code addresses (each table once)."""
    used = {table for table in tables for i in listing.instructions
            if i.target is None and i.operand is not None and i.mode not in ("imm", "rel") and table.holds(i.operand)}
    return sum(table.size for table in used)
