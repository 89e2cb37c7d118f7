"""The routine's world (retro.routines.world) on one Machine: traps at the mock and exit addresses,
a device on the bus per hardware address; and a scene's chip registers that an input, output or block
of the spec would land on (an error naming both)."""

from __future__ import annotations

from collections.abc import Callable

from retro.cpu.machine import RETURN_TRAP
from retro.cpu.traps import TRAP_OPCODE, install_on_mpu
from retro.errors import InputError, RunError
from retro.routines.places import Place
from retro.routines.world import MAX_RECORDED, Hardware, Mock, World, call_user, function_effects, whole


class _Memory:
    """The machine's memory as a function mock sees it: read-only, by index or slice."""

    def __init__(self, memory: list[int]) -> None:
        self._memory = memory

    def __getitem__(self, index):
        if isinstance(index, slice):
            return bytes(self._memory[index])
        return self._memory[int(index) & 0xFFFF]

    def __len__(self) -> int:
        return len(self._memory)


class MachineWorld:
    """The world on one Machine: traps at the mock and exit addresses, a device per hardware address;
    `reset(cycle)` before each call, then what the call did: `counts`, `calls`, `written`,
    `trap_cycles` (cycles the traps ran, which the timing model adds)."""

    def __init__(self, world: World, machine, spec: str) -> None:
        self.world = world
        self.machine = machine
        self.spec = spec
        self.start = 0
        self.counts = {m.name: 0 for m in world.mocks}
        self.calls: dict[str, list[dict]] = {m.name: [] for m in world.mocks}
        self.reads = {h.name: 0 for h in world.hardware}
        self.written: dict[str, list[int]] = {h.name: [] for h in world.hardware}
        self.trap_cycles = 0
        actions: dict[int, Callable] = {m.address: self._mock_action(m) for m in world.mocks}
        actions.update({address: self._exit for address in world.exits})
        install_on_mpu(machine.mpu, actions)
        self.actions = actions
        for hardware in world.hardware:
            machine.attach(_HardwareDevice(self, hardware), hardware.address, hardware.address)

    def describe_trap(self, address: int) -> str:
        mock = next((m for m in self.world.mocks if m.address == address), None)
        return f"(mock {mock.name}: {mock.cycles} cycles)" if mock is not None else "(exit)"

    def place_traps(self) -> None:
        """Write the trap byte at every mock and exit address (after the program and memory blocks)."""
        for address in self.actions:
            self.machine.memory[address] = TRAP_OPCODE

    def reset(self, cycle: int) -> None:
        self.start = cycle
        self.trap_cycles = 0
        for name in self.counts:
            self.counts[name] = 0
            self.calls[name] = []
        for name in self.reads:
            self.reads[name] = 0
            self.written[name] = []

    def _exit(self, mpu) -> int:
        mpu.pc, mpu.sp = RETURN_TRAP, self.machine.stop_s  # the run loop's stop: the call has ended here
        return 0

    def _mock_action(self, mock: Mock) -> Callable:
        recorded = mock.name in self.world.recorded

        def action(mpu) -> int:
            count = self.counts[mock.name] = self.counts[mock.name] + 1
            if recorded:
                if count > MAX_RECORDED:
                    raise RunError(f"mock {mock.name} was called more than {MAX_RECORDED:,} times in one call")
                self.calls[mock.name].append({text: _machine_place(mpu, place) for text, place in mock.args})
            if mock.function is None:
                for register, value in mock.registers:
                    setattr(mpu, register, value)
                mpu.p = (mpu.p | mock.flags_set) & ~mock.flags_clear
                for address, value in mock.writes:
                    mpu.WriteByte(address, value)
            else:
                self._call_function(mpu, mock, count)
            low = mpu.stPop()  # the mock's RTS
            mpu.pc = ((mpu.stPop() << 8 | low) + 1) & 0xFFFF
            self.trap_cycles += mock.cycles
            return mock.cycles
        return action

    def _call_function(self, mpu, mock: Mock, count: int) -> None:
        state = {"a": mpu.a, "x": mpu.x, "y": mpu.y, "p": mpu.p, "s": mpu.sp, "count": count,
                 "cycle": mpu.processorCycles - self.start, "memory": _Memory(mpu.memory)}
        registers, flags_set, flags_clear, writes = function_effects(mock, state, self.spec)
        for register, value in registers:
            setattr(mpu, register, value)
        mpu.p = (mpu.p | flags_set) & ~flags_clear
        for address, value in writes:
            mpu.WriteByte(address, value)

    def value(self, place: Place) -> int:
        """A world output's byte after the call (a count's byte, or the k-th value written)."""
        if place.kind == "count":
            kind, _, name = place.register.partition(":")
            count = self.counts[name] if kind == "calls" else len(self.written[name])
            return (count >> (8 * place.bit)) & 0xFF
        values = self.written[place.register]
        return values[place.bit] if place.bit < len(values) else 0

    def recorded_calls(self) -> dict[str, list[dict]]:
        return {name: list(self.calls[name]) for name in self.world.recorded}


def _machine_place(mpu, place: Place) -> int:
    if place.kind == "register":
        return getattr(mpu, place.register)
    if place.kind == "flag":
        return int(bool(mpu.p & place.bit))
    return mpu.memory[place.address]


class _HardwareDevice:
    """One scripted address on Machine's bus: reads from the script, writes recorded (and kept in RAM,
    so a read with no script gives the last value written)."""

    def __init__(self, world: MachineWorld, hardware: Hardware) -> None:
        self.world = world
        self.hardware = hardware
        self.memory = world.machine.memory

    def read(self, address: int, cycle: int) -> int:
        world, hardware = self.world, self.hardware
        count = world.reads[hardware.name]
        world.reads[hardware.name] = count + 1
        if hardware.reads is not None:
            return hardware.reads[min(count, len(hardware.reads) - 1)]
        if hardware.function is None:
            return self.memory[address]
        state = {"count": count, "cycle": cycle - world.start}
        where = f"{world.spec}: hardware.{hardware.name}.function"
        value = call_user(hardware.function, hardware.parameters, state, where, f"read {count}")
        return whole(value, 0xFF, where, count)

    def write(self, address: int, value: int, cycle: int) -> None:
        written = self.world.written[self.hardware.name]
        if len(written) >= MAX_RECORDED:
            raise RunError(f"hardware {self.hardware.name} (${address:04X}) was written more than "
                           f"{MAX_RECORDED:,} times in one call")
        written.append(value)
        self.memory[address] = value

    def peek(self, address: int) -> int:
        return self.memory[address]


def chip_overlaps(routine, devices: list[tuple[int, int, object]], scene: str) -> None:
    """An input, output or memory block on a chip register of the attached scene is an error naming both
    (the chip answers those reads, so the value placed there would be silently hidden)."""
    def chip_at(address: int):
        return next(((start, end, device) for start, end, device in devices
                     if start <= address <= end and not isinstance(device, _HardwareDevice)), None)

    named = [(f"inputs.{p.name}.at", p) for p in routine.inputs] + [(f"outputs.{p.name}.at", p) for p in routine.outputs]
    for key, port in named:
        for place in port.places:
            if place.kind == "memory" and (chip := chip_at(place.address)) is not None:
                raise _overlap_error(routine, key, place.address, chip, scene)
    for block in routine.memory:
        for address in range(block.address, block.address + max(block.size, 1)):
            if (chip := chip_at(address)) is not None:
                raise _overlap_error(routine, f"memory.{block.name}.at", address, chip, scene)
    for hardware in routine.world.hardware:
        if (chip := chip_at(hardware.address)) is not None:
            raise _overlap_error(routine, f"hardware.{hardware.name}.at", hardware.address, chip, scene)


def _overlap_error(routine, key: str, address: int, chip, scene: str) -> InputError:
    start, end, device = chip
    name = getattr(device, "chip_name", type(device).__name__)
    return InputError(f"{routine.spec_path}: {key}: ${address:04X} is a register of the {name} "
                      f"(${start:04X}-${end:04X}) of the scene {scene}: the chip answers there, not the spec's value")
