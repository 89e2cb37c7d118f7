"""Where a routine's inputs go, worked out once per routine: `InputPlan` puts one case (numbers, for
Machine) or a column block (arrays, one element per lane, for the batched and compiled engines) in
place with the same code; `ViaPlan` places the inputs and outputs a case locates itself (on the
stack, in a table slot, behind a pointer: retro.routines.places.Via)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from retro.cpu.machine import ENTRY_S, STACK_BASE
from retro.cpu.mpu import FLAG_U
from retro.routines.entry import EntryState
from retro.routines.spec import Port, Routine


def case_byte(value: Sequence[int], k: int) -> int:
    """Byte k of one case's table input."""
    return value[k]


def column_byte(value: np.ndarray, k: int) -> np.ndarray:
    """Byte k of a table input, per lane of a column block."""
    return value[:, k]


@dataclass(frozen=True)
class InputPlan:
    """Where each input goes, worked out once per routine so a call does no lookups by name; the
    same plan puts one case (numbers) or a column block (arrays, one element per lane) in place."""

    registers: tuple[tuple[int, str, int], ...]  # (input index, register, byte shift)
    flags: tuple[tuple[int, int], ...]  # (input index, P bit)
    bytes: tuple[tuple[int, int, int], ...]  # (input index, address, byte shift)
    tables: tuple[tuple[int, tuple[int, ...]], ...]  # (input index, addresses)
    base_flags: int  # P before the flag inputs: the default flags without those the inputs set
    output_addresses: tuple[int, ...]  # output places in memory (restored before each Machine call)
    base_registers: tuple[tuple[str, int], ...] = (("a", 0), ("x", 0), ("y", 0))  # before the inputs ([entry])
    vias: "ViaPlan | None" = None  # inputs and outputs placed by the case (stack, table slot, pointer)
    entry_s: int = ENTRY_S  # S at entry when no input sets it

    def __post_init__(self) -> None:  # what every call starts from, worked out once (a call is microseconds)
        object.__setattr__(self, "_start", {**dict(self.base_registers), "s": self.entry_s})
        object.__setattr__(self, "_s_varies", any(register == "s" for _, register, _ in self.registers))

    @property
    def s_varies(self) -> bool:
        """An input sets S (each call, or each lane, has its own)."""
        return self._s_varies

    @classmethod
    def of(cls, routine: Routine, image: Sequence[int] | None = None, salt: int = 0) -> "InputPlan":
        registers, flags, places, tables = [], [], [], []
        for index, port in enumerate(routine.inputs):
            if port.via is not None:
                continue  # placed by ViaPlan
            if port.flag:
                flags.append((index, port.places[0].bit))
            elif port.table:
                tables.append((index, tuple(p.address for p in port.places)))
            else:
                for byte, place in enumerate(port.places):
                    if place.kind == "register":
                        registers.append((index, place.register, 8 * byte))
                    else:
                        places.append((index, place.address, 8 * byte))
        forced = 0
        for _, bit in flags:
            forced |= bit
        outputs = sorted({place.address for port in routine.outputs for place in port.places if place.kind == "memory"})
        vias = ViaPlan.of(routine, image, salt) if any(p.via for p in routine.inputs + routine.outputs) else None
        entry = EntryState.of(routine.entry_state, routine.inputs)
        return cls(tuple(registers), tuple(flags), tuple(places), tuple(tables),
                   (entry.flags | FLAG_U) & ~forced, tuple(outputs),
                   tuple(entry.registers.items()), vias, routine.entry_s)

    def place(self, values: Sequence, table_byte: Callable, write: Callable,
              entry: tuple[dict, object, int] | None = None, scatter: Callable | None = None,
              select: Callable | None = None, write_table: Callable | None = None) -> tuple[dict[str, object], object]:
        """Put `values` (one per input: numbers, or arrays of lanes) in place: `write(address, byte)`
        for every memory byte as it is made (a block's arrays are consumed while in cache), and
        (register values, P) returned; `table_byte(value, k)` is byte k of a table input's value.
        `entry`: (free registers by name, free P bits, the free bits' mask) of an entry-state run
        (retro.routines.entry), replacing the baseline's values of the registers and flags no input
        or `[entry]` sets. Inputs placed by the case go through `scatter(address, byte)` (the
        address: a number, or one per lane) and `select(condition, a, b)` (a where b otherwise).
        `write_table(addresses, value)`: a table input's bytes at once (one case: the value is its bytes),
        instead of `write` byte by byte."""
        for index, address, shift in self.bytes:
            write(address, (values[index] >> shift) & 0xFF)
        for index, addresses in self.tables:
            if write_table is not None:
                write_table(addresses, values[index])
                continue
            for k, address in enumerate(addresses):
                write(address, table_byte(values[index], k))
        if self.vias is not None:
            self.vias.place(values, table_byte, scatter or write, select or _case_select)
        registers = dict(self._start)
        p = self.base_flags
        if entry is not None:
            free, bits, mask = entry
            registers.update(free)
            p = (p & ~mask) | bits
        for index, register, shift in self.registers:
            if register == "s":
                registers["s"] = values[index]
                continue
            registers[register] |= (values[index] >> shift) & 0xFF
        for index, bit in self.flags:
            p |= (values[index] != 0) * bit
        return registers, p


def _slots(routine: Routine, port: Port) -> dict[int, list[tuple[int, int]]]:
    """A table slot port: every address its index may pick -> the (slot, byte) pairs placed there."""
    via = port.via
    wrap = 0xFF if via.base < 0x100 else 0xFFFF
    index = routine.inputs[via.index_input].values
    at: dict[int, list[tuple[int, int]]] = {}
    for slot in (index.listed if index.listed is not None else range(index.lo, index.hi + 1)):
        for i in range(len(port.places)):
            at.setdefault((via.base + slot + i) & wrap, []).append((slot, i))
    return at


def _case_select(condition, a, b):
    return a if condition else b


def _byte(port: Port, value, i: int, table_byte: Callable):
    """Byte i of an input's value: of a table, or of a little-endian number."""
    return table_byte(value, i) if port.table else (value >> (8 * i)) & 0xFF


FILLER_MIX = (0x2D, 0x65, 0x1F, 0x9D)  # small odd multipliers: every term stays far below 2^63 (ints and int64 alike)


@dataclass(frozen=True)
class ViaPlan:
    """Where the inputs and outputs placed by the case go (retro.routines.places.Via), worked out once:
    the same arithmetic places one case (ints) or a column block (arrays: one address per lane). An
    input in a slot of a table fills every other slot its index may pick with a value other than its
    own (from the case and the seed), so that a routine reading the wrong slot reads a wrong value."""

    routine: Routine
    pointers: dict  # the address of a pointer no input sets -> its value in memory after `init`
    salt: int
    slot_maps: dict  # (section, port index) of a table slot port -> {address: [(slot, byte), ...]}

    @classmethod
    def of(cls, routine: Routine, image: Sequence[int] | None, salt: int) -> "ViaPlan":
        pointers = {}
        for port in routine.inputs + routine.outputs:
            via = port.via
            if via is not None and via.mode == "pointer" and via.pointer_input < 0:
                high = (via.base + 1) & (0xFF if via.base < 0x100 else 0xFFFF)
                pointers[via.base] = (image[via.base] | image[high] << 8) if image is not None else 0
        slot_maps = {(section, k): _slots(routine, port) for section, ports in (("in", routine.inputs),
                                                                                ("out", routine.outputs))
                     for k, port in enumerate(ports) if port.via is not None and port.via.mode == "indexed"}
        return cls(routine, pointers, salt & 0xFFFF, slot_maps)

    def address(self, via, values: Sequence, i: int):
        """The address of byte i of a port placed by `via`, for a case (or per lane of a block)."""
        if via.mode == "stack":
            s = values[via.s_input] if via.s_input >= 0 else self.routine.entry_s
            return STACK_BASE | ((s + via.base + i) & 0xFF)
        index = values[via.index_input] if via.index_input >= 0 else 0
        if via.mode == "indexed":
            return (via.base + index + i) & (0xFF if via.base < 0x100 else 0xFFFF)
        pointer = values[via.pointer_input] if via.pointer_input >= 0 else self.pointers[via.base]
        return (pointer + via.offset + index + i) & 0xFFFF

    def place(self, values: Sequence, table_byte: Callable, scatter: Callable, select: Callable) -> None:
        for k, port in enumerate(self.routine.inputs):
            via = port.via
            if via is None:
                continue
            value = values[k]
            if via.mode != "indexed":
                for i in range(len(port.places)):
                    scatter(self.address(via, values, i), _byte(port, value, i, table_byte))
                continue
            index = values[via.index_input]
            for address, placed in self.slot_maps["in", k].items():
                slot, i = placed[0]
                byte = _byte(port, value, i, table_byte)
                mixed = (byte * FILLER_MIX[0] + slot * FILLER_MIX[1] + i * FILLER_MIX[2] + (index & 0xFF) * FILLER_MIX[3]
                         + (value & 0xFFFF if not port.table else 0) + self.salt + k)
                chosen = byte ^ (1 + (mixed ^ (mixed >> 5)) % 255)  # never the slot's own byte
                for slot, i in placed:
                    chosen = select(index == slot, _byte(port, value, i, table_byte), chosen)
                scatter(address, chosen)

    def touched(self, values: Sequence) -> list[int]:
        """Every address the case's ports placed by the case take (a table slot port: every slot):
        what Machine restores before the next call, so that each call starts as a batch lane does."""
        found = []
        for section, ports in (("in", self.routine.inputs), ("out", self.routine.outputs)):
            for k, port in enumerate(ports):
                if port.via is not None:
                    found += (list(self.slot_maps[section, k]) if port.via.mode == "indexed" else
                              [self.address(port.via, values, i) for i in range(len(port.places))])
        return found

    def outputs(self, values: Sequence) -> dict[int, list]:
        """Output index -> the addresses of its bytes for this case (or per lane)."""
        return {k: [self.address(port.via, values, i) for i in range(len(port.places))]
                for k, port in enumerate(self.routine.outputs) if port.via is not None}
