"""A block of cases run at once: on the batched core (retro.cpu.batch; every lane starts from the
memory as it stood after `init`, with its inputs in place through the runner's InputPlan) or on the
compiled engine (retro.cpu.compiled; the calls it leaves run on the batched core). Both give a
`BatchOutcome`; a block too big for the lanes' memory is run in halves."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from retro.cpu.batch import BatchCpu, LaneCoverage, LaneError
from retro.cpu.lane_memory import LaneMemoryFull
from retro.cpu.machine import (
    RETURN_TRAP,
    STACK_BASE,
    interrupt_entry_flags,
    push_interrupt_frame,
    push_return_trap,
    return_s,
)
from retro.cpu.mpu import FLAG_B, FLAG_U
from retro.cpu.variants import VARIANTS
from retro.routines.grid import one_row
from retro.routines.input_plan import column_byte
from retro.routines.outputs import port_values
from retro.routines.world import WORLD_PLACES
from retro.routines.world_lanes import BatchWorld

if TYPE_CHECKING:
    from retro.routines.runner import RoutineRunner


@dataclass(frozen=True)
class BatchOutcome:
    """What a batch of calls did: per output an array (n,) or (n, bytes), cycles, and per case the
    retro.cpu.batch.LaneError that stopped it (0: returned); `coverage`: what the lanes ran, when asked."""

    outputs: list
    cycles: np.ndarray
    error: np.ndarray
    stolen: np.ndarray | None = None  # per case, the cycles a scene's chip held the CPU (None: no chip)
    coverage: LaneCoverage | None = None
    mock_calls: list | None = None  # per case, the calls of the mocks the reference takes (retro.routines.world)


def _widen(values) -> np.ndarray:
    return np.asarray(values, dtype=np.int64)


def _table(columns: list) -> np.ndarray:
    return np.stack(columns, axis=1).astype(np.int64)


def run_batch(runner: RoutineRunner, columns: list, coverage: bool = False, first_lanes: bool = False,
              entry: tuple[dict, np.ndarray, int] | None = None) -> BatchOutcome:
    """Every case of a column block on the batched core (RoutineRunner.run_batch); when the lanes'
    memory is full, the two halves one after the other, joined as one outcome."""
    n = len(columns[0])
    try:
        return _run_lanes(runner, columns, n, coverage, first_lanes, entry)
    except LaneMemoryFull:
        if n <= 1:
            raise
    half = n // 2
    halves = [None, None] if entry is None else [
        ({k: v[:half] for k, v in entry[0].items()}, entry[1][:half], entry[2]),
        ({k: v[half:] for k, v in entry[0].items()}, entry[1][half:], entry[2])]
    first = runner.run_batch([c[:half] for c in columns], coverage, first_lanes, halves[0])
    second = runner.run_batch([c[half:] for c in columns], coverage, first_lanes, halves[1])
    return _joined(first, second, half)


def _joined(first: BatchOutcome, second: BatchOutcome, half: int) -> BatchOutcome:
    if first.coverage is not None:
        first.coverage.merge(second.coverage, lane_offset=half)
    return BatchOutcome([np.concatenate(pair) for pair in zip(first.outputs, second.outputs)],
                        np.concatenate([first.cycles, second.cycles]),
                        np.concatenate([first.error, second.error]),
                        None if first.stolen is None else np.concatenate([first.stolen, second.stolen]),
                        coverage=first.coverage,
                        mock_calls=None if first.mock_calls is None else first.mock_calls + second.mock_calls)


def _run_lanes(runner: RoutineRunner, columns: list, n: int, coverage: bool = False, first_lanes: bool = False,
               entry: tuple[dict, np.ndarray, int] | None = None) -> BatchOutcome:
    routine = runner.routine
    image = bytearray(runner.call_image)
    fixed_s = None if runner.plan.s_varies else runner.fixed_entry_s
    stack_pointer = None if fixed_s is None else _push_entry_frame(image, routine.world.enter, fixed_s)
    cpu = BatchCpu(routine.cpu, image, n, coverage=coverage, first_lanes=first_lanes)
    memory = cpu.memory
    world = None if routine.world.empty else BatchWorld(routine.world, cpu, runner.written_kept, str(routine.spec_path))
    registers, p = runner.plan.place(columns, column_byte, memory.fill, entry,
                                     scatter=lambda address, byte: memory.write(slice(None), address, byte),
                                     select=np.where)
    s = registers.pop("s")
    for name, value in registers.items():
        lanes = getattr(cpu, name)
        lanes |= np.asarray(value).astype(lanes.dtype)
    cpu.p[:] = (runner._entry_p(p) | FLAG_U) & ~FLAG_B  # as Machine sets P
    stop = _enter_lanes(runner, cpu, s, fixed_s, stack_pointer)
    if world is not None:
        world.stack_top = stop  # where an exit ends the call
    if runner.vic is not None:  # the scene's timeline: each lane stalls as Machine would from the start
        cpu.bus_stall = runner.bus_stalls
    cpu.watch = _fact_watches(runner)
    cpu.call(runner.entry, runner.limit, RETURN_TRAP, stop)
    if world is not None:
        world.finish()
    located = runner.plan.vias.outputs(columns) if runner.plan.vias is not None else None
    outputs = port_values(routine.outputs, {"a": cpu.a, "x": cpu.x, "y": cpu.y}, cpu.p, cpu.read,
                          widen=_widen, table=_table, world=None if world is None else world.value, located=located,
                          read_at=lambda address: _every_lane(memory.read(slice(None), address), n))
    calls = world.recorded_calls() if world is not None and routine.world.recorded else None
    return BatchOutcome(outputs, cpu.cycles, cpu.error, cpu.stolen if runner.vic is not None else None,
                        coverage=cpu.coverage, mock_calls=calls)


def _push_entry_frame(image: bytearray, enter: str, s: int) -> int:
    """The caller's frame on the stack every lane shares (a JSR's return trap, or an interrupt's
    return address and a slot for P); S after it."""
    return push_return_trap(image, s) if enter == "jsr" else push_interrupt_frame(image, 0, return_s(s))


def _enter_lanes(runner: RoutineRunner, cpu: BatchCpu, s, fixed_s: int | None, stack_pointer: int | None):
    """S of every lane at entry, and the S at which a lane's call has returned."""
    if fixed_s is None:  # each lane's return address where its own JSR put it, as Machine does
        cpu.sp[:] = s
        push_return_trap(_LaneStores(cpu.memory), cpu.sp.copy())
        return return_s(cpu.sp.copy())
    world = runner.routine.world
    if world.enter != "jsr":  # the interrupt sequence: P pushed (per lane), I set, its 7 cycles counted
        cpu.memory.fill(STACK_BASE | (stack_pointer + 1), cpu.p.copy())
        cpu.p[:] = interrupt_entry_flags(VARIANTS[runner.routine.cpu], cpu.p)
        cpu.cycles[:] = world.entry_cycles
    cpu.sp[:] = stack_pointer
    return return_s(fixed_s)


def _fact_watches(runner: RoutineRunner) -> dict:
    """The spec's stated facts, held against every lane at their addresses."""
    image = runner.call_image
    return {pc: (lambda lanes, fact=fact, opcode=image[pc]: fact.broken(lanes.a, lanes.x, lanes.y, lanes.p, opcode))
            for pc, fact in runner.watched_facts.items()}


def compiled_routine(runner: RoutineRunner, free: tuple = ()):
    """The routine compiled (`retro.cpu.compiled`), made on first use and again when the code bytes
    changed (set_memory); Untranslatable when the compiled engine does not take it. `free`: an
    entry-state run's free registers ("a", "x", "y") and P bits, each set from a column after the
    inputs' (`run_compiled(..., entry=...)`: another function, compiled once)."""
    from retro.cpu.compiled import SET_FLAG, SET_REGISTERS, compile_routine
    from retro.cpu.mpu import FLAG_D

    held = runner._compiled if not free else runner._compiled_free.get(free)
    if held is not None and (held[2] == runner.call_image or all(runner.call_image[a] == b for a, b in held[1])):
        return held[0]
    image = bytes(runner.call_image)
    plan = runner.plan
    inputs_at = [address for _, address, _ in plan.bytes] + [a for _, addresses in plan.tables for a in addresses]
    trapped = bytearray(image)
    push_return_trap(trapped)
    places = tuple((index, shift, address) for index, address, shift in plan.bytes)  # read from the columns per call
    sets = tuple([(index, shift, SET_REGISTERS.index(register)) for index, register, shift in plan.registers]
                 + [(index, bit, SET_FLAG) for index, bit in plan.flags])
    inputs = len(runner.routine.inputs)
    sets += tuple((inputs + k, 0, SET_REGISTERS.index(place)) if isinstance(place, str) else (inputs + k, place, SET_FLAG)
                  for k, place in enumerate(free))
    routine = compile_routine(bytes(trapped), runner.entry, runner.routine.cpu, RETURN_TRAP, inputs_at,
                              inputs + len(free), places, sets,
                              lanes=tuple(a for _, addresses in plan.tables for a in addresses),
                              outputs=tuple(int(a) for a in plan.output_addresses),
                              decimal_entry=bool(plan.base_flags & FLAG_D), results=_results(runner.routine.outputs))
    held = (routine, [(a, image[a]) for a in sorted(routine.translation.code_bytes)], image)
    if free:
        runner._compiled_free[free] = held
    else:
        runner._compiled = held
    return routine


class _Code:
    """An expression of the compiled function's variables: `port_values` run on these (instead of
    arrays) writes what the function computes per call for an output, so how an output is read from
    the registers, P and memory has one home (retro.routines.outputs) on every engine."""

    def __init__(self, text: str) -> None:
        self.text = text

    def _with(self, symbol: str, other) -> _Code:
        return _Code(f"({self.text} {symbol} {other.text if isinstance(other, _Code) else int(other)})")

    def __and__(self, other) -> _Code:
        return self._with("&", other)

    def __or__(self, other) -> _Code:
        return self._with("|", other)

    def __lshift__(self, other) -> _Code:
        return self._with("<<", other)

    def __ne__(self, other) -> _Code:  # type: ignore[override]
        return self._with("!=", other)


def _in_function(port) -> bool:
    """Whether the compiled function computes this output itself (a number from registers, P or fixed
    memory bytes; not a table, an output placed by the case or a world's)."""
    return not port.table and port.via is None and port.places[0].kind not in WORLD_PLACES


def _results(ports) -> tuple[tuple[str, str], ...]:
    """What the compiled function writes per call: each output it computes itself (`_in_function`),
    then the registers the others read."""
    computed = [port for port in ports if _in_function(port)]
    expressions = port_values(computed, {name: _Code(name) for name in "axy"}, _Code("p"),
                              lambda address: _Code(f"mem[{int(address)}]"),
                              widen=lambda value: _Code(f"np.int64({value.text if isinstance(value, _Code) else int(value)})"),
                              table=None)
    return (tuple((f"out{k}", code.text) for k, code in enumerate(expressions))
            + tuple((name, name) for name in "axyp" if any(not _in_function(port) for port in ports)))


CACHE_LINE = 64  # bytes


def lane_row_width(n: int) -> int:
    """The width of a lane-bytes row for n lanes: n rounded up to an odd number of cache lines. The kernel
    reads one byte of every row per call; rows a power of two apart (8,192 lanes) all fall in the same
    cache set and evict each other on every call (pixel's 126 rows: 3.5 ms a block of 8,192 calls, 1.1 ms
    with rows 8,256 bytes apart, measured)."""
    lines = -(-n // CACHE_LINE)
    return CACHE_LINE * (lines + 1 - lines % 2)


def _lane_bytes(plan, columns: list, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The table inputs as (addresses, one row of bytes per address): lane i's bytes in column i of each
    row, rows `lane_row_width(n)` wide (the columns past n are never read: the kernel runs the calls of
    the case columns, n). Each table cast to bytes in one contiguous pass, then turned (a strided cast of
    int64 column by column cost pixel's 126 bytes 0.5 us a call, this 0.14); a table that is one row
    repeated (grid.one_row) set a byte per row. The kernel reads registers, flags and single bytes from
    the case columns itself."""
    lane_addr = np.asarray([address for _, addresses in plan.tables for address in addresses], dtype=np.int64)
    lane_bytes = np.empty((len(lane_addr), lane_row_width(n)), dtype=np.uint8)
    row = 0
    for index, addresses in plan.tables:
        column = columns[index][:n, :len(addresses)]
        same = one_row(column)
        rows = lane_bytes[row:row + len(addresses), :n]
        if same is not None:  # one row repeated: each address's one byte over every lane (wrapped as astype)
            rows[:] = same.astype(np.uint8)[:, None]
        else:
            rows[:] = column.astype(np.uint8).T
        row += len(addresses)
    return lane_addr, lane_bytes


def run_compiled(runner: RoutineRunner, columns: list,
                 entry: tuple[dict, np.ndarray, int] | None = None) -> BatchOutcome:
    """Every case of a column block on the compiled engine; calls it leaves (`fallbacks`, by
    reason) run on the batched core. `entry` as for run_batch: the free registers and P bits of an
    entry-state run, per lane (read from columns of their own, over a base with them cleared)."""
    n = len(columns[0])
    plan = runner.plan
    start = dict(plan.base_registers)
    p = plan.base_flags
    free: tuple = ()
    extra: list = []
    if entry is not None:
        registers, bits, mask = entry
        bit_list = [1 << k for k in range(8) if mask >> k & 1]
        free = (*sorted(registers), *bit_list)
        extra = [registers[name] for name in sorted(registers)] + [bits & bit for bit in bit_list]
        start.update(dict.fromkeys(registers, 0))
        p &= ~mask
    compiled = compiled_routine(runner, free)
    lane_addr, lane_bytes = _lane_bytes(plan, columns, n)
    flat = tuple(np.ascontiguousarray(c if c.ndim == 1 else c[:, 0], dtype=np.int64) for c in [*columns, *extra])
    base = np.asarray([start["a"], start["x"], start["y"], p], dtype=np.int64)
    s = runner.fixed_entry_s
    image = _entered_image(runner, s)
    out_addr = np.asarray(plan.output_addresses, dtype=np.int64)
    done = compiled.run(image, flat, base, s, runner.limit, RETURN_TRAP, return_s(s), out_addr, lane_addr, lane_bytes)
    outputs = _outputs(runner.routine.outputs, done, out_addr)
    status = done["status"]
    cycles = done["cycles"]
    if not n or not status.max():  # the common case: every call returned (one pass, no scan for the others)
        return BatchOutcome(outputs, cycles, np.zeros(n, dtype=np.int8))
    error = np.where(status == LaneError.BUDGET, LaneError.BUDGET, 0).astype(np.int8)
    _rerun_fallbacks(runner, columns, status, outputs, cycles, error, entry)
    return BatchOutcome(outputs, cycles, error)


def _entered_image(runner: RoutineRunner, s: int) -> bytes:
    """The runner's call image with the return trap pushed for entry with S = `s` (push_return_trap), kept
    while the call image stays the same: a sweep's blocks share one (no copy of the 64 KiB per block, and
    the compiled routine finds its working memory made for the very same bytes)."""
    held = runner._entered_image
    if held is None or held[0] != s or held[1] != runner.call_image:
        image = bytearray(runner.call_image)
        push_return_trap(image, s)
        held = runner._entered_image = (s, bytes(runner.call_image), bytes(image))
    return held[2]


def _outputs(ports, done: dict, out_addr: np.ndarray) -> list:
    """Per output, its values: computed by the compiled function (`_results`), else read from the
    registers and output bytes it wrote."""
    others = [port for port in ports if not _in_function(port)]
    if others:
        column_of = {int(address): k for k, address in enumerate(out_addr)}
        out_bytes = done["bytes"]
        read = iter(port_values(others, {name: done[name] for name in "axy"}, done["p"],
                                lambda address: out_bytes[column_of[address]].astype(np.int64),
                                widen=_widen, table=_table))
    computed = iter(done[f"out{k}"] for k in range(len(ports) - len(others)))
    return [next(computed) if _in_function(port) else next(read) for port in ports]


def _rerun_fallbacks(runner: RoutineRunner, columns: list, status: np.ndarray, outputs: list, cycles: np.ndarray,
                     error: np.ndarray, entry: tuple | None = None) -> None:
    """The calls the compiled engine left (counted by reason in `runner.fallbacks`) run again on the
    batched core (with their entry state), their results written over the compiled block's."""
    from retro.cpu.compiled import FALLBACK

    if not len(status) or status.max() < FALLBACK:  # the common case: no scan for the calls left
        return
    left = np.flatnonzero(status >= FALLBACK)
    if not len(left):
        return
    for code, count in zip(*np.unique(status[left], return_counts=True)):
        runner.fallbacks[int(code)] = runner.fallbacks.get(int(code), 0) + int(count)
    if entry is not None:
        entry = ({name: values[left] for name, values in entry[0].items()}, entry[1][left], entry[2])
    batch = runner.run_batch([c[left] for c in columns], entry=entry)
    for output, redone in zip(outputs, batch.outputs):
        output[left] = redone
    cycles[left] = batch.cycles
    error[left] = batch.error


class _LaneStores:
    """`memory[address] = byte` on every lane of a batch (an address per lane): push_return_trap's view."""

    def __init__(self, memory) -> None:
        self.memory = memory

    def __setitem__(self, address, byte) -> None:
        self.memory.write(slice(None), address, byte)


def _every_lane(value, lanes: int) -> np.ndarray:
    return np.full(lanes, value, dtype=np.int64) if isinstance(value, (int, np.integer)) else value
