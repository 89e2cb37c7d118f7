"""A routine's size in bytes: its reachable instructions (the entry's and init's, with their
subroutines), the generated lookup tables and `[memory]` blocks they read, and the storage tables the
caller fills; and the address an executed instruction read its operand from (what `blocks_read` sees)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from retro.assembler import requested_tables
from retro.cpu.machine import STORES
from retro.cpu.timing import TimingError, timing_of
from retro.program import Program
from retro.routines.world import NO_WORLD, World
from retro.tables import GENERATORS, STORAGE_TABLES


@dataclass(frozen=True)
class Size:
    code_bytes: int  # from the origin up to the first generated table (the program's length without them)
    table_bytes: int  # lookup tables and the `[memory]` blocks the routine read (storage the caller fills: not)
    storage_bytes: int
    table_blocks: tuple[tuple[str, int], ...] = ()  # (name, bytes) of the `[memory]` blocks among the tables


IMMEDIATE_LOAD_A = 0xA9  # lda #>table: how an init routine sets up a pointer's high byte
NO_DATA = frozenset({"JMP", "JSR", "BRK", "RTS", "RTI"})


def data_address(read, pc: int, x: int, y: int, pointer: int, cpu: str) -> int | None:
    """The address the instruction at pc reads its operand from (registers before it, `pointer`: the
    word of an (indirect),Y instruction as recorded), or None when it reads none."""
    try:
        op = timing_of(read(pc), cpu)
    except TimingError:
        return None
    if op.mnemonic in STORES or op.mnemonic in NO_DATA:
        return None
    mode, lo = op.mode, read((pc + 1) & 0xFFFF)
    if mode == "zpg":
        return lo
    if mode in ("zpx", "zpy"):
        return (lo + (x if mode == "zpx" else y)) & 0xFF
    if mode in ("abs", "abx", "aby"):
        return ((lo | read((pc + 2) & 0xFFFF) << 8) + (x if mode == "abx" else y if mode == "aby" else 0)) & 0xFFFF
    if mode == "iny":
        return (pointer + y) & 0xFFFF
    if mode in ("inx", "zpi"):  # the pointer as memory holds it after the call (not recorded)
        at = (lo + (x if mode == "inx" else 0)) & 0xFF
        return read(at) | read((at + 1) & 0xFF) << 8
    return None


def routine_code(read, entries: list[int], within: tuple[int, int], cpu: str = "6510",
                 world: World = NO_WORLD) -> dict[int, int]:
    """{address: length} of every instruction reachable from the entries (following branches, JMP and
    JSR into the program), as the static analysis decodes them (an interrupt handler's RTI and the
    world's exits end a path); code it does not follow counts none."""
    from retro.cpu.flow import instruction_lengths, return_opcodes

    return instruction_lengths(read, entries, within, cpu, skip_undecodable=True, ends=return_opcodes(world.enter != "jsr"),
                               exits=frozenset(world.exits))


def program_size(program: Program, source_text: str | None, entries: list[int], read, cpu: str = "6510",
                 world: World = NO_WORLD, blocks: Sequence[tuple[str, int, int]] = ()) -> Size:
    """The routine's bytes: its reachable instructions (the entry's and init's, with their subroutines)
    and the generated tables they name (by address, or by `#>table` for pointers set up at init)."""
    code = routine_code(read, entries, (program.origin, program.end), cpu, world)
    spans = _table_spans(program, source_text)
    used = _tables_named(code, spans, read)
    lookup = sum(_table_length(n) for n in used if n not in STORAGE_TABLES)
    storage = sum(_table_length(n) for n in used if n in STORAGE_TABLES)
    counted = [spans[n] for n in used]  # a `[memory]` block inside a generated table is that table
    read_blocks = [(name, start, size) for name, start, size in blocks
                   if not any(first <= start < end for first, end in counted)]
    return Size(code_bytes=sum(code.values()), table_bytes=lookup + sum(size for _, _, size in read_blocks),
                storage_bytes=storage, table_blocks=tuple((name, size) for name, _, size in read_blocks))


def _table_length(name: str) -> int:
    return len(GENERATORS[name]())


def _table_spans(program: Program, source_text: str | None) -> dict[str, tuple[int, int]]:
    """The generated tables the source requests and the program holds -> (first address, end)."""
    names = requested_tables(source_text) if source_text else []
    return {n: (program.symbols[n], program.symbols[n] + _table_length(n)) for n in names if n in program.symbols}


def _tables_named(code: dict[int, int], spans: dict[str, tuple[int, int]], read: Callable) -> set[str]:
    """The tables an instruction names: an absolute operand inside one, or `lda #>table`."""
    used = set()
    for pc, length in code.items():
        if length == 3:
            operand = read((pc + 1) & 0xFFFF) | read((pc + 2) & 0xFFFF) << 8
            used.update(name for name, (first, end) in spans.items() if first <= operand < end)
        elif length == 2 and read(pc) == IMMEDIATE_LOAD_A:
            operand = read((pc + 1) & 0xFFFF)
            used.update(name for name, (first, _) in spans.items() if operand == first >> 8)
    return used
