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
from dataclasses import dataclass, field

import numpy as np

from retro.cpu.batch import BatchCpu, Lanes
from retro.cpu.disassembly import opcode_table
from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_V, FLAG_Z
from retro.cpu.timing import BRANCH_CONDITIONS, BRANCH_TAKEN_CYCLES
from retro.optimize.code import Instruction, Listing, opcode_of
from retro.optimize.effects import ALL_MEMORY, INDEXED_READ_MODES, READ_MODIFY_WRITE, STORES
from retro.routines.places import Place, Port

FLAG_BITS = {"C": FLAG_C, "Z": FLAG_Z, "I": FLAG_I, "D": FLAG_D, "V": FLAG_V, "N": FLAG_N}
BRK = 0x00
IMPLIED_POOL = ("TAX", "TAY", "TXA", "TYA", "INX", "INY", "DEX", "DEY", "CLC", "SEC", "CLV")
SHIFT_POOL = ("ASL", "LSR", "ROL", "ROR")
IMMEDIATE_POOL = ("LDA", "LDX", "LDY", "ADC", "SBC", "AND", "ORA", "EOR", "CMP", "CPX", "CPY")
MEMORY_POOL = ("LDA", "LDX", "LDY", "STA", "STX", "STY", "ADC", "SBC", "AND", "ORA", "EOR", "CMP", "CPX",
               "CPY", "BIT", "INC", "DEC")
CONSTANTS = (0x00, 0x01, 0x7F, 0x80, 0xFF)
MAX_IMMEDIATES = 16
BRANCHES = ("BCC", "BCS", "BEQ", "BNE", "BMI", "BPL", "BVC", "BVS")
BRANCH_CYCLES = 2  # not taken; taken: + BRANCH_TAKEN_CYCLES (a page crossed: one more, which the proof measures)
END = "<end>"  # the target of a synthesised branch: the routine's RTS
MAX_STATES = 200_000
CHUNK_STATES = 512  # states stepped at once (x the sample's lanes: bounded memory)  # distinct prefix states kept per window (memory stays bounded)


@dataclass
class State:
    a: np.ndarray
    x: np.ndarray
    y: np.ndarray
    p: np.ndarray
    memory: dict  # address -> per-lane bytes
    done: np.ndarray | None = None  # lanes that branched to the end (their state is final); None: none
    cycles: np.ndarray | None = None  # per lane, cycles so far (None: 0)

    def filled(self) -> "State":
        if self.done is not None and self.cycles is not None:
            return self
        zeros = np.zeros(self.a.shape, dtype=np.int32)
        return State(self.a, self.x, self.y, self.p, self.memory,
                     zeros.astype(bool) if self.done is None else self.done,
                     zeros if self.cycles is None else self.cycles)


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
    """Instructions run on machine states with the batched core's handlers: a State's arrays are
    (lanes,) for one state or (states, lanes) for many, run as one group of states x lanes."""

    def __init__(self, cpu: str, image: bytes, lanes: int, at: int) -> None:
        self.variant, self.image, self.at = cpu, image, at
        self.opcode = opcode_of(cpu)
        self.handlers = BatchCpu(cpu, image, 1).handlers
        self.cycles = {opcode: op.cycles for opcode, op in opcode_table(cpu).items()}
        self._cpus: dict[int, tuple] = {}  # lanes -> (BatchCpu, S, cycles): made once, reused by every step

    def _cpu(self, n: int) -> tuple:
        """A machine of n lanes to run one instruction on. Reused: a step fills every byte its
        instruction may read before it runs, so what an earlier step left behind is never read."""
        made = self._cpus.get(n)
        if made is None:
            if len(self._cpus) > 8:
                self._cpus.clear()
            made = self._cpus[n] = (BatchCpu(self.variant, self.image, n), np.full(n, 0xFD, dtype=np.int32),
                                    np.zeros(n, dtype=np.int64))
        return made

    def step(self, state: State, instruction: Instruction) -> State:
        shape = state.a.shape
        n = state.a.size
        opcode = self.opcode[(instruction.mnemonic, instruction.mode)]
        state = state.filled()
        done = state.done
        if instruction.mode == "rel":  # a branch to the end: the lanes it takes are done
            bit, value = BRANCH_CONDITIONS[opcode]
            taken = (((state.p & bit) != 0) == bool(value)) & ~done
            spent = np.where(done, 0, BRANCH_CYCLES + taken * BRANCH_TAKEN_CYCLES)
            return State(state.a, state.x, state.y, state.p, state.memory, done | taken,
                         (state.cycles + spent).astype(np.int32))
        cpu, sp, cycles = self._cpu(n)
        operand = instruction.operand or 0
        address = operand if instruction.mode in ("zpg", "abs") else None
        if address is not None:
            cpu.memory.fill(address, state.memory[address].reshape(n))
        elif instruction.mode in INDEXED_READ_MODES:  # the address is per lane: every byte the state holds
            for at, values in state.memory.items():
                cpu.memory.fill(at, values.reshape(n))
        cycles.fill(0)
        # the handlers assign new arrays to a, x, y and p, never change them in place: no copies
        group = Lanes(cpu, slice(None), state.a.reshape(n), state.x.reshape(n), state.y.reshape(n),
                      state.p.reshape(n), sp, cycles)
        self.handlers[opcode](group, self.at, operand & 0xFF, operand >> 8)
        memory = state.memory
        if address is not None and (instruction.mnemonic in STORES or instruction.mnemonic in
                                    ("INC", "DEC", "ASL", "LSR", "ROL", "ROR")):
            memory = dict(memory)
            value = cpu.memory.read(slice(None), address)
            memory[address] = (np.full(n, value, dtype=np.int32) if isinstance(value, int)
                               else value.astype(np.int32)).reshape(shape)
            if done.any():
                memory[address] = np.where(done, state.memory[address], memory[address])
        spent = group.cycles.reshape(shape)  # the handler's own cycles: page crossings of indexed reads too
        if not done.any():
            def lanes(values, old):
                values = np.asarray(values, dtype=np.int32)
                return values.reshape(shape) if values.size == n else np.broadcast_to(values, shape)
            return State(lanes(group.a, state.a), lanes(group.x, state.x), lanes(group.y, state.y),
                         lanes(group.p, state.p), memory, done, (state.cycles + spent).astype(np.int32))

        def lanes(values, old):
            return np.where(done, old, np.broadcast_to(np.asarray(values, dtype=np.int32), (n,)).reshape(shape))
        return State(lanes(group.a, state.a), lanes(group.x, state.x), lanes(group.y, state.y),
                     lanes(group.p, state.p), memory, done, (state.cycles + np.where(done, 0, spent)).astype(np.int32))


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


def target_matches(state: State, target: State, live: frozenset) -> np.ndarray | bool:
    """Whether the state (or each of many states: arrays (states, lanes)) equals the target on every
    sample case in what is live."""
    ok = np.ones(state.a.shape[:-1], dtype=bool)
    for register in ("a", "x", "y"):
        if register.upper() in live:
            ok &= (getattr(state, register) == getattr(target, register)).all(axis=-1)
    mask = 0
    for name, bit in FLAG_BITS.items():
        if name in live:
            mask |= bit
    if mask:
        ok &= ((state.p & mask) == (target.p & mask)).all(axis=-1)
    for address, values in target.memory.items():
        if address in live or ALL_MEMORY in live:
            ok &= (state.memory[address] == values).all(axis=-1)
    return ok


def _rows(state: State, rows: np.ndarray) -> State:
    state = state.filled()
    return State(state.a[rows], state.x[rows], state.y[rows], state.p[rows],
                 {a: v[rows] for a, v in state.memory.items()}, state.done[rows], state.cycles[rows])


def _slice(state: State, low: int, high: int) -> State:
    """States low..high-1 of many (views: nothing copied)."""
    state = state.filled()
    return State(state.a[low:high], state.x[low:high], state.y[low:high], state.p[low:high],
                 {a: v[low:high] for a, v in state.memory.items()}, state.done[low:high], state.cycles[low:high])


def _keys(state: State, addresses) -> list[bytes]:
    """One key per state of many (rows of (states, lanes) arrays): its bytes on every sample case
    and which cases are done; of memory only `addresses` (bytes no instruction of the pool writes
    are the same in every state)."""
    parts = [state.a, state.x, state.y, state.p, state.filled().done] + [state.memory[a] for a in addresses]
    matrix = np.ascontiguousarray(np.concatenate([part.astype(np.uint8) for part in parts], axis=1))
    return matrix.view(np.dtype((np.void, matrix.shape[1]))).ravel().tolist()


def _order(objective: str, cycles: np.ndarray, size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`rank` as two arrays (what orders first, then what breaks ties), one element per state."""
    worst = cycles.max(axis=-1)
    if objective == "bytes":
        return size, worst
    if objective == "mean":
        return cycles.mean(axis=-1), size
    return worst, size


@dataclass
class Enumeration:
    """What one window's enumeration did: sequences run (candidates tested), goals found in order."""

    tested: int = 0
    states: int = 0
    found: list = field(default_factory=list)  # (rank, instructions), best first
    complete: bool = True  # every sequence up to the length within the bound was tried


def rank(objective: str, cycles: np.ndarray, size) -> list[tuple]:
    """Per state of many (cycles: (states, lanes)), what the objective orders by, smaller first."""
    worst = cycles.max(axis=-1)
    mean = cycles.mean(axis=-1)
    size = np.broadcast_to(np.asarray(size), worst.shape)
    if objective == "bytes":
        return list(zip(size.tolist(), worst.tolist()))
    if objective == "mean":
        return list(zip(mean.tolist(), size.tolist()))
    return list(zip(worst.tolist(), size.tolist()))


def enumerate_window(executor: Executor, cpu: str, start: State, target: State, live: frozenset,
                     pool: list[Instruction], length: int, bound: tuple, deadline: float,
                     objective: str = "worst") -> Enumeration:
    """Breadth-first, one prefix per distinct state (the cheapest), every instruction of the pool
    run at once on all the states of a level; goals are sequences of at most `length` instructions
    reaching `target` on `live` whose rank (`rank`: cycles per sample case and bytes) is below
    `bound`. A branch of the pool goes to the end: the cases it takes keep their state."""
    result = Enumeration()
    first = _lift(start).filled()
    if target_matches(first, target, live)[0]:
        result.found.append(((0, 0), ()))
        return result
    key_addresses = sorted(a for a in start.memory if any(
        i.operand == a and i.mode in ("zpg", "abs") and (i.mnemonic in STORES or i.mnemonic in READ_MODIFY_WRITE)
        for i in pool))
    seen = {_keys(first, key_addresses)[0]: (0, 0)}
    frontier, sequences, sizes = first, [()], np.zeros(1, dtype=np.int64)
    for level in range(length):
        last = level == length - 1  # the last level keeps no states: only its goals count
        next_states, next_sequences, next_sizes = [], [], []
        for instruction in pool:
            if time.monotonic() > deadline:
                result.complete = False
                return _sorted(result)
            for rows in range(0, len(sizes), CHUNK_STATES):  # bounded memory: a chunk of states at a time
                if time.monotonic() > deadline:
                    result.complete = False
                    return _sorted(result)
                end = min(rows + CHUNK_STATES, len(sizes))
                part = frontier if end - rows == len(sizes) else _slice(frontier, rows, end)
                kept = _expand(executor, part, instruction, sizes[rows:end], sequences[rows:end],
                               target, live, bound, objective, seen, result, last, key_addresses)
                if kept is not None:
                    next_states.append(kept[0])
                    next_sequences += kept[1]
                    next_sizes += kept[2]
        if not next_states:
            break
        frontier = State(*(np.concatenate([getattr(s, r) for s in next_states]) for r in ("a", "x", "y", "p")),
                         {a: np.concatenate([s.memory[a] for s in next_states]) for a in start.memory},
                         np.concatenate([s.done for s in next_states]), np.concatenate([s.cycles for s in next_states]))
        sequences, sizes = next_sequences, np.asarray(next_sizes, dtype=np.int64)
    result.states = len(seen)
    return _sorted(result)


def _expand(executor: Executor, frontier: State, instruction: Instruction, sizes: np.ndarray, sequences: list,
            target: State, live: frozenset, bound: tuple, objective: str, seen: dict, result: Enumeration,
            last: bool = False, key_addresses=()):
    """One instruction after each of the states: goals go to `result.found`; (states, sequences,
    sizes) kept for the next level, or None."""
    new = executor.step(frontier, instruction)
    spent = sizes + instruction.length
    first, second = _order(objective, new.cycles, spent)
    result.tested += len(sizes)
    inside = (first < bound[0]) | ((first == bound[0]) & (second < bound[1]))
    if instruction.mode == "rel" and inside.any():  # a case that ended must have ended right: it cannot change
        inside &= target_matches(_masked(new, target), target, live)
    within = np.flatnonzero(inside)
    if not len(within):
        return None
    if len(within) < len(sizes):
        new = _rows(new, within)
    ranks = list(zip(first[within].tolist(), second[within].tolist()))
    goals = target_matches(new, target, live)
    if last:
        for k in np.flatnonzero(goals).tolist():
            result.found.append((ranks[k], sequences[within[k]] + (instruction,)))
        return None
    finished = new.done.all(axis=-1)
    keep, next_sequences, next_sizes = [], [], []
    goals, finished, rows = goals.tolist(), finished.tolist(), within.tolist()
    for k, key in enumerate(_keys(new, key_addresses)):
        old = seen.get(key)
        rank_k = ranks[k]
        if old is not None and old <= rank_k:
            continue
        if len(seen) < MAX_STATES:
            seen[key] = rank_k
        else:
            result.complete = False
        sequence = sequences[rows[k]] + (instruction,)
        if goals[k]:
            result.found.append((rank_k, sequence))
            continue
        if finished[k]:
            continue  # every case has ended and it is not the target
        keep.append(k)
        next_sequences.append(sequence)
        next_sizes.append(int(spent[rows[k]]))
    if not keep:
        return None
    return _rows(new, np.asarray(keep)), next_sequences, next_sizes


def _masked(state: State, target: State) -> State:
    """The state with the cases still running given the target's values (only ended cases compared)."""
    done = state.done

    def pick(values, wanted):
        return np.where(done, values, wanted)
    return State(pick(state.a, target.a), pick(state.x, target.x), pick(state.y, target.y), pick(state.p, target.p),
                 {a: pick(v, target.memory[a]) if a in target.memory else v for a, v in state.memory.items()},
                 done, state.cycles)


def _lift(state: State) -> State:
    return State(state.a[None, :], state.x[None, :], state.y[None, :], state.p[None, :],
                 {a: v[None, :] for a, v in state.memory.items()})


def _sorted(result: Enumeration) -> Enumeration:
    result.found.sort(key=lambda f: f[0])
    return result
