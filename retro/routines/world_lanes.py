"""The routine's world (retro.routines.world) on one BatchCpu: traps at the mock and exit addresses
(a function mock called lane by lane), hooks on the lane memory for the hardware addresses; per-lane
call counts, writes and, for the mocks the reference takes, every call's arguments."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from retro.cpu.machine import CALL_STACK_TOP, RETURN_TRAP
from retro.cpu.traps import install_on_batch
from retro.errors import RunError
from retro.routines.places import Place
from retro.routines.world import MAX_RECORDED, Hardware, Mock, World, function_effects


class BatchWorld:
    """The world on one BatchCpu (mocks with stated effects, exits): per-lane call counts and, for
    the mocks the reference takes, every call's arguments."""

    def __init__(self, world: World, cpu, written_kept: dict[str, int] | None = None, spec: str = "",
                 stack_top: int = CALL_STACK_TOP) -> None:
        from retro.cpu.batch import LaneError

        self.world = world
        self.cpu = cpu
        self.spec = spec
        self.stack_top = stack_top  # S the call started from (the entry-state runs vary it): an exit ends there
        self.counts = {m.name: np.zeros(cpu.lanes, dtype=np.int64) for m in world.mocks}
        self.records: dict[str, list[tuple[np.ndarray, dict]]] = {m.name: [] for m in world.mocks}
        actions: dict[int, Callable] = {m.address: self._mock_action(m) for m in world.mocks}
        actions.update({address: self._exit for address in world.exits})
        install_on_batch(cpu, actions, lambda g, pc: g.stop(pc, LaneError.JAM))
        self.hardware = {h.address: _LaneHardware(h, cpu.lanes, (written_kept or {}).get(h.name, 0))
                         for h in world.hardware}
        if self.hardware:
            self._hook_memory(cpu.memory)

    def _hook_memory(self, memory) -> None:
        """Reads and writes of the hardware addresses go through the script and the record (this
        LaneMemory only, while the lanes run: `finish` ends it before the outputs are read)."""
        read, write, lanes_of = memory.read, memory.write, memory.lanes_of
        hardware = self.hardware
        addresses = np.asarray(sorted(hardware))

        def hooked_read(idx, address):
            if isinstance(address, (int, np.integer)):
                device = hardware.get(int(address))
                return read(idx, address) if device is None else device.read(lanes_of(idx), read(idx, address))
            values = read(idx, address)
            hit = np.isin(address, addresses)
            if hit.any():
                values = np.asarray(values).copy()
                lanes = lanes_of(idx)
                for target in np.unique(address[hit]).tolist():
                    at = address == target
                    values[at] = hardware[target].read(lanes[at], values[at])
            return values

        def hooked_write(idx, address, value) -> None:
            if isinstance(address, (int, np.integer)):
                device = hardware.get(int(address))
                if device is not None:
                    device.write(lanes_of(idx), value)
            else:
                hit = np.isin(address, addresses)
                if hit.any():
                    lanes = lanes_of(idx)
                    for target in np.unique(address[hit]).tolist():
                        at = address == target
                        hardware[target].write(lanes[at], value if isinstance(value, (int, np.integer)) else value[at])
            write(idx, address, value)

        memory.read, memory.write = hooked_read, hooked_write
        self._unhook = lambda: (delattr(memory, "read"), delattr(memory, "write"))

    def finish(self) -> None:
        """The lanes have run: reads of the memory are the host's again (outputs)."""
        if self.hardware:
            self._unhook()

    def _exit(self, g):
        stop = self.stack_top  # one S for every lane, or each lane's own (an input S)
        g.sp = (np.asarray(stop)[g.ids] if np.ndim(stop) else np.full(len(g), stop)).astype(np.int32)
        return RETURN_TRAP

    def _mock_action(self, mock: Mock) -> Callable:
        recorded = mock.name in self.world.recorded
        counts = self.counts[mock.name]

        def action(g):
            lanes = g.cpu.memory.lanes_of(g.ids)
            counts[lanes] += 1
            if recorded:
                if counts[lanes].max() > MAX_RECORDED:
                    raise RunError(f"mock {mock.name} was called more than {MAX_RECORDED:,} times in one call")
                self.records[mock.name].append((lanes.copy(), {text: _lane_place(g, place) for text, place in mock.args}))
            if mock.function is not None:
                self._call_function(g, mock, lanes, counts)
            else:
                for register, value in mock.registers:
                    setattr(g, register, np.full(len(g), value, dtype=np.int32))
                g.p = (g.p | mock.flags_set) & ~mock.flags_clear
                for address, value in mock.writes:
                    g.write(address, value)
            g.cycles += mock.cycles
            low = g.pull()  # the mock's RTS
            target = ((g.pull() << 8 | low) + 1) & 0xFFFF
            return _uniform(target)
        return action

    def _call_function(self, g, mock: Mock, lanes: np.ndarray, counts: np.ndarray) -> None:
        """A function mock, called lane by lane in lane order with each lane's state (as Machine calls
        it case by case: a function that depends only on what it is given answers the same)."""
        n = len(g)
        registers = {name: np.array(np.broadcast_to(getattr(g, name), n), dtype=np.int32) for name in ("a", "x", "y", "p")}
        sp = np.broadcast_to(g.sp, n)
        memory = g.cpu.memory
        for j, lane in enumerate(lanes.tolist()):
            state = {"a": int(registers["a"][j]), "x": int(registers["x"][j]), "y": int(registers["y"][j]),
                     "p": int(registers["p"][j]), "s": int(sp[j]), "count": int(counts[lane]),
                     "cycle": int(g.cycles[j]), "memory": _LaneMemoryView(memory, lane)}
            changed, flags_set, flags_clear, writes = function_effects(mock, state, self.spec)
            for register, value in changed:
                registers[register][j] = value
            registers["p"][j] = (registers["p"][j] | flags_set) & ~flags_clear
            for address, value in writes:
                memory.write(np.asarray([lane]), address, value)  # through the hardware hooks, as WriteByte
        g.a, g.x, g.y, g.p = registers["a"], registers["x"], registers["y"], registers["p"]

    def value(self, place: Place) -> np.ndarray:
        if place.kind == "written":
            device = next(d for d in self.hardware.values() if d.hardware.name == place.register)
            return device.kept[:, place.bit]
        kind, _, name = place.register.partition(":")
        if kind == "writes":
            device = next(d for d in self.hardware.values() if d.hardware.name == name)
            return (device.writes >> (8 * place.bit)) & 0xFF
        return (self.counts[name] >> (8 * place.bit)) & 0xFF

    def recorded_calls(self) -> list[dict[str, list[dict]]]:
        """Per lane, the calls of every recorded mock (as MachineWorld.recorded_calls gives one)."""
        lanes = [{name: [] for name in self.world.recorded} for _ in range(self.cpu.lanes)]
        for name in self.world.recorded:
            for ids, values in self.records[name]:
                columns = {text: np.broadcast_to(v, len(ids)).tolist() for text, v in values.items()}
                for j, lane in enumerate(ids.tolist()):
                    lanes[lane][name].append({text: column[j] for text, column in columns.items()})
        return lanes


class _LaneMemoryView:
    """One lane's memory as a function mock sees it (read-only, what memory holds: no scripted read)."""

    def __init__(self, memory, lane: int) -> None:
        self._memory, self._lane = memory, np.asarray([lane])

    def _byte(self, address: int) -> int:
        return int(np.asarray(type(self._memory).read(self._memory, self._lane, address & 0xFFFF)).ravel()[0])

    def __getitem__(self, index):
        if isinstance(index, slice):
            return bytes(self._byte(a) for a in range(0x10000)[index])
        return self._byte(int(index))

    def __len__(self) -> int:
        return 0x10000


class _LaneHardware:
    """One scripted address on the batched core: per lane its read count, its write count and the
    first `kept` values written."""

    def __init__(self, hardware: Hardware, lanes: int, kept: int) -> None:
        self.hardware = hardware
        self.reads = np.zeros(lanes, dtype=np.int64)
        self.writes = np.zeros(lanes, dtype=np.int64)
        self.kept = np.zeros((lanes, kept), dtype=np.int64)
        self.script = None if hardware.reads is None else np.asarray(hardware.reads, dtype=np.int32)

    def read(self, lanes: np.ndarray, stored):
        """The values the lanes read (`stored`: what memory holds there, the last value written)."""
        count = self.reads[lanes]
        self.reads[lanes] = count + 1
        if self.script is None:
            return stored
        return self.script[np.minimum(count, len(self.script) - 1)]

    def write(self, lanes: np.ndarray, value) -> None:
        count = self.writes[lanes]
        if count.size and count.max() >= MAX_RECORDED:
            raise RunError(f"hardware {self.hardware.name} (${self.hardware.address:04X}) was written more than "
                           f"{MAX_RECORDED:,} times in one call")
        kept = count < self.kept.shape[1]
        if kept.any():
            values = np.broadcast_to(np.asarray(value), lanes.shape)
            self.kept[lanes[kept], count[kept]] = values[kept]
        self.writes[lanes] = count + 1


def _uniform(values):
    if isinstance(values, (int, np.integer)):
        return int(values)
    return int(values[0]) if len(values) and values.min() == values.max() else values


def _lane_place(g, place: Place):
    if place.kind == "register":
        return np.asarray(getattr(g, place.register)).copy()
    if place.kind == "flag":
        return ((np.asarray(g.p) & place.bit) != 0).astype(np.int64)
    memory = g.cpu.memory  # what memory holds, as Machine's record reads RAM: never a scripted read
    return np.asarray(type(memory).read(memory, g.ids, place.address)).copy()

