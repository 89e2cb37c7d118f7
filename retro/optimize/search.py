"""The enumerative search: windows of a routine replaced by cheaper straight-line code.

For a window (instructions [start, stop) with no branch target inside), the machine state on each
sample case where the routine reaches the window is taken from a run of the routine with BRK at the
window's first byte (the batched core stops the lanes there). Sequences are enumerated breadth-first
over a pruned instruction set (the routine's own operands and immediates, a few constants, the
transfers and flag instructions), one instruction at a time on those states with the batched core's
own handlers (retro.cpu.batch), keeping one prefix per distinct machine state on the samples and
only prefixes within the cycle bound. A sequence whose end state equals the original window's on
everything live after the window is a candidate; it is then run as a whole routine on the samples,
and proven (retro.optimize.evaluate). "Synthesis" is the window of a whole short routine: its end
state must equal the reference's answers."""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from retro.cpu.batch import BatchCpu, Lanes
from retro.cpu.disassembly import opcode_table
from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_V, FLAG_Z
from retro.optimize.code import Instruction, Listing, assemble, opcode_of
from retro.optimize.effects import ALL_MEMORY, STORES, effects, windowable
from retro.routines.places import Place, Port
from retro.routines.spec import Routine

FLAG_BITS = {"C": FLAG_C, "Z": FLAG_Z, "I": FLAG_I, "D": FLAG_D, "V": FLAG_V, "N": FLAG_N}
BRK = 0x00
IMPLIED_POOL = ("TAX", "TAY", "TXA", "TYA", "INX", "INY", "DEX", "DEY", "CLC", "SEC", "CLV")
SHIFT_POOL = ("ASL", "LSR", "ROL", "ROR")
IMMEDIATE_POOL = ("LDA", "LDX", "LDY", "ADC", "SBC", "AND", "ORA", "EOR", "CMP", "CPX", "CPY")
MEMORY_POOL = ("LDA", "LDX", "LDY", "STA", "STX", "STY", "ADC", "SBC", "AND", "ORA", "EOR", "CMP", "CPX",
               "CPY", "BIT", "INC", "DEC")
CONSTANTS = (0x00, 0x01, 0x7F, 0x80, 0xFF)
MAX_IMMEDIATES = 16
MAX_STATES = 200_000  # distinct prefix states kept per window (memory stays bounded)


@dataclass
class State:
    a: np.ndarray
    x: np.ndarray
    y: np.ndarray
    p: np.ndarray
    memory: dict  # address -> per-lane bytes

    def key(self) -> bytes:
        return b"".join([self.a.tobytes(), self.x.tobytes(), self.y.tobytes(), self.p.tobytes()]
                        + [self.memory[a].tobytes() for a in sorted(self.memory)])


def state_ports(addresses) -> tuple[Port, ...]:
    """Outputs that read the whole machine state a window can see: A, X, Y, each flag, the addresses."""
    ports = [Port(r, (Place("register", register=r),)) for r in ("a", "x", "y")]
    ports += [Port(f"flag_{name}", (Place("flag", bit=bit),)) for name, bit in FLAG_BITS.items()]
    ports += [Port(f"m_{a:04x}", (Place("memory", address=a),)) for a in addresses]
    return tuple(ports)


def state_of(outputs: list, addresses, lanes: np.ndarray) -> State:
    a, x, y = (np.asarray(outputs[k][lanes], dtype=np.int32) for k in range(3))
    p = np.zeros(len(lanes), dtype=np.int32) | 0x20
    for k, bit in enumerate(FLAG_BITS.values()):
        p |= np.where(outputs[3 + k][lanes] != 0, bit, 0).astype(np.int32)
    memory = {address: np.asarray(outputs[9 + k][lanes], dtype=np.int32) for k, address in enumerate(addresses)}
    return State(a, x, y, p, memory)


class Executor:
    """One instruction at a time on a State, with the batched core's handlers."""

    def __init__(self, cpu: str, image: bytes, lanes: int, at: int) -> None:
        self.cpu = BatchCpu(cpu, image, max(lanes, 1))
        self.at = at
        self.table = opcode_table(cpu)
        self.opcode = opcode_of(cpu)

    def step(self, state: State, instruction: Instruction) -> State:
        opcode = self.opcode[(instruction.mnemonic, instruction.mode)]
        operand = instruction.operand or 0
        memory = self.cpu.memory
        address = operand if instruction.mode in ("zpg", "abs") else None
        if address is not None:
            memory.fill(address, state.memory[address])
        group = Lanes(self.cpu, slice(None), state.a.copy(), state.x.copy(), state.y.copy(), state.p.copy(),
                      np.full(len(state.a), 0xFD, dtype=np.int32), np.zeros(len(state.a), dtype=np.int64))
        self.cpu.handlers[opcode](group, self.at, operand & 0xFF, operand >> 8)
        written = dict(state.memory)
        if address is not None and (instruction.mnemonic in STORES or instruction.mnemonic in
                                    ("INC", "DEC", "ASL", "LSR", "ROL", "ROR")):
            value = memory.read(slice(None), address)
            written[address] = (np.full(len(state.a), value, dtype=np.int32) if isinstance(value, int)
                                else value.astype(np.int32))
        return State(np.asarray(group.a, dtype=np.int32), np.asarray(group.x, dtype=np.int32),
                     np.asarray(group.y, dtype=np.int32), np.asarray(group.p, dtype=np.int32), written)


def cycles_of(cpu: str, instruction: Instruction) -> int:
    return opcode_table(cpu)[opcode_of(cpu)[(instruction.mnemonic, instruction.mode)]].cycles


def instruction_pool(cpu: str, listing: Listing, window: tuple[Instruction, ...], addresses) -> list[Instruction]:
    """The instructions the search tries: the window's own, the transfers and flag instructions,
    immediates the routine uses (and their neighbours and complements) with a few constants, and
    the direct addresses of the routine and its ports."""
    forms = opcode_of(cpu)
    pool: dict[Instruction, None] = dict.fromkeys(window)
    for name in IMPLIED_POOL:
        pool[Instruction(name, "imp")] = None
    for name in SHIFT_POOL:
        pool[Instruction(name, "acc")] = None
    seen = [i.operand for i in listing.instructions if i.mode == "imm"]
    immediates = list(dict.fromkeys(seen + [(v + d) & 0xFF for v in seen for d in (1, -1)] + [v ^ 0xFF for v in seen]
                                    + list(CONSTANTS)))[:MAX_IMMEDIATES]
    for name in IMMEDIATE_POOL:
        for value in immediates:
            pool[Instruction(name, "imm", value)] = None
    for address in addresses:
        mode = "zpg" if address < 0x100 else "abs"
        for name in MEMORY_POOL:
            pool[Instruction(name, mode, address)] = None
    return [i for i in pool if (i.mnemonic, i.mode) in forms]


def target_matches(state: State, target: State, live: frozenset) -> bool:
    for register in ("a", "x", "y"):
        if register.upper() in live and not np.array_equal(getattr(state, register), getattr(target, register)):
            return False
    mask = 0
    for name, bit in FLAG_BITS.items():
        if name in live:
            mask |= bit
    if mask and not np.array_equal(state.p & mask, target.p & mask):
        return False
    for address, values in target.memory.items():
        if (address in live or ALL_MEMORY in live) and not np.array_equal(state.memory[address], values):
            return False
    return True


@dataclass
class Enumeration:
    """What one window's enumeration did: sequences run (candidates tested), goals found in order."""

    tested: int = 0
    states: int = 0
    found: list = field(default_factory=list)  # (cycles, bytes, instructions)
    complete: bool = True  # every sequence up to the length within the bound was tried


def enumerate_window(executor: Executor, cpu: str, start: State, target: State, live: frozenset,
                     pool: list[Instruction], length: int, bound: tuple[int, int], deadline: float,
                     by_bytes: bool = False) -> Enumeration:
    """Breadth-first, one prefix per distinct state; goals are sequences of at most `length`
    instructions reaching `target` on `live` and costing less than `bound` ((cycles, bytes), or
    (bytes, cycles) with `by_bytes`)."""
    result = Enumeration()
    costs = [(cycles_of(cpu, i), i.length) for i in pool]
    seen = {start.key(): (0, 0)}
    frontier = [(start, (), 0, 0)]
    if target_matches(start, target, live):
        result.found.append((0, 0, ()))
        return result
    for _ in range(length):
        following = []
        for state, sequence, cycles, size in frontier:
            for instruction, (c, b) in zip(pool, costs):
                total_c, total_b = cycles + c, size + b
                cost = (total_b, total_c) if by_bytes else (total_c, total_b)
                if cost >= bound:
                    continue
                if time.monotonic() > deadline:
                    result.complete = False
                    return result
                new = executor.step(state, instruction)
                result.tested += 1
                key = new.key()
                old = seen.get(key)
                if old is not None and old <= cost:
                    continue
                if len(seen) < MAX_STATES:
                    seen[key] = cost
                else:
                    result.complete = False
                found = sequence + (instruction,)
                if target_matches(new, target, live):
                    result.found.append((*cost, found) if not by_bytes else (cost[1], cost[0], found))
                    continue
                following.append((new, found, total_c, total_b))
        frontier = following
        if not frontier:
            break
    result.states = len(seen)
    result.found.sort(key=lambda f: (f[1], f[0]) if by_bytes else (f[0], f[1]))
    return result
