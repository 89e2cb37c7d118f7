"""The routine's world: what a spec says about everything outside the routine's own bytes.

- **Mocks** (`[mocks]`): a JSR target outside the program whose effect the spec states: registers
  and flags it returns, bytes it writes, the cycles it costs, or a Python function of the machine
  state (run under the sandbox's guards). Every call is counted, its arguments (registers, flags,
  memory named in `args`) recorded; outputs can be the count (`{ calls = NAME }`) and the reference
  may take the list of calls by the mock's name.
- **Hardware** (`[hardware]`): an address whose reads the spec scripts (a list of values, the last
  one held, or a function of the read count and cycle) and whose writes are recorded; outputs can be
  the values written (`{ writes = NAME, size = N }`) or their count (`{ writes = NAME }`).
- **Entry and exit** (`[program] interrupt`, `[program] exit`): a routine entered as an IRQ or NMI
  handler (the interrupt sequence's pushes and 7 cycles, I set; it ends at the RTI that pops that
  frame), and addresses whose reaching ends the call (a JMP to a named exit instead of an RTS).

Both engines run all of it with the same results, through traps (retro.cpu.traps: the trap byte
written at every mock and exit address) and, for hardware, a device on Machine's bus or hooks on the
batched core's lane memory (a function mock is called lane by lane there); what the batched core
cannot run (a hardware function, timed per read; an NMOS read-modify-write of hardware) is said by
`batch_refusal`, and the check then runs on Machine and
says why. docs/specs.md, "The routine's world", is the user's view.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from retro.cpu.bus import FIRST_DEVICE_ADDRESS
from retro.cpu.machine import CALL_STACK_TOP, RETURN_TRAP
from retro.cpu.mpu import INTERRUPT_CYCLES, RMW_MNEMONICS
from retro.cpu.variants import VARIANTS
from retro.cpu.traps import TRAP_OPCODE, install_on_batch, install_on_mpu
from retro.errors import InputError, RunError
from retro.fields import Fields, describe
from retro.program import Program
from retro.routines.places import FLAGS, REGISTERS, Place, Port, places_of, resolve
from retro.routines.sandbox import UserCodeError, shown

ENTRY_KINDS = ("irq", "nmi")  # `[program] interrupt`: the routine is that interrupt's handler
MOCK_KEYS = {"at", "cycles", "args", "writes", "function", *REGISTERS, *FLAGS}
HARDWARE_KEYS = {"at", "reads", "function"}
OUTPUT_KEYS = {"calls", "writes", "size"}
MAX_MOCK_CYCLES = 1 << 20
MAX_READS_LISTED = 1 << 16
MAX_WRITES_OUTPUT = 256  # values of a `writes` output
MAX_RECORDED = 1 << 16  # calls of one mock (or writes to one address) recorded in one call of the routine
COUNT_PLACES = 2  # a count output is a 16-bit number
FUNCTION_MOCK_ARGUMENTS = ("a", "x", "y", "p", "s", "count", "cycle", "memory")
HARDWARE_FUNCTION_ARGUMENTS = ("count", "cycle")
WORLD_PLACES = ("count", "written")  # Place kinds of world outputs (a count's byte, a written value)
_RESULT_KEYS = {*REGISTERS, *FLAGS, "writes"}


# ---- plain data ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class Mock:
    """What a JSR to `address` does instead of running code there: its effects, then an RTS."""

    name: str
    address: int
    cycles: int  # from the callee's first cycle through its RTS (the caller's JSR is the caller's)
    registers: tuple[tuple[str, int], ...] = ()  # ("a", 7): registers it returns
    flags_set: int = 0
    flags_clear: int = 0
    writes: tuple[tuple[int, int], ...] = ()  # (address, byte) it stores
    args: tuple[tuple[str, Place], ...] = ()  # what each call records: (the spec's text, where)
    function: Callable | None = None  # a Python function of the machine state (its effects instead)
    parameters: tuple[str, ...] = ()  # of FUNCTION_MOCK_ARGUMENTS, those the function takes


@dataclass(frozen=True)
class Hardware:
    """An address whose reads are scripted and whose writes are recorded."""

    name: str
    address: int
    reads: tuple[int, ...] | None = None  # the values of the reads in order, the last one held
    function: Callable | None = None  # (count, cycle) -> byte
    parameters: tuple[str, ...] = ()
    rmw_at: int | None = None  # an NMOS read-modify-write of it in the program (its double write: Machine only)


@dataclass(frozen=True)
class World:
    mocks: tuple[Mock, ...] = ()
    hardware: tuple[Hardware, ...] = ()
    enter: str = "jsr"  # "jsr", "irq" or "nmi" (retro.cpu.machine.ENTRIES)
    exits: tuple[int, ...] = ()  # reaching one of these ends the call
    recorded: frozenset[str] = frozenset()  # mocks whose calls are kept (the reference takes them)

    @property
    def empty(self) -> bool:
        return not (self.mocks or self.hardware or self.exits) and self.enter == "jsr"

    @property
    def entry_cycles(self) -> int:
        """Cycles counted before the routine's first instruction: the interrupt sequence's."""
        return 0 if self.enter == "jsr" else INTERRUPT_CYCLES

    def batch_refusal(self) -> str | None:
        """Why the batched core cannot run this world (None: it can)."""
        for hardware in self.hardware:
            if hardware.function is not None:
                return f"hardware.{hardware.name}.function is a Python function, run per read on Machine"
            if hardware.rmw_at is not None:
                return (f"hardware.{hardware.name} (${hardware.address:04X}) is read-modified-written at "
                        f"${hardware.rmw_at:04X}, whose double write Machine models")
        return None

    def mock_costs(self) -> dict[int, int]:
        """Cycles of each mocked JSR target (its body through the RTS), for the static bounds."""
        return {m.address: m.cycles for m in self.mocks}


NO_WORLD = World()


# ---- reading a spec -------------------------------------------------------------------------------

def parse_world(r: Fields, doc: dict, program: Program, seconds: int, load_function: Callable,
                cpu: str = "6510") -> World:
    """`[mocks]`, `[hardware]` and `[program] interrupt` / `exit` -> a World (every error names its key)."""
    program_doc = doc.get("program", {})
    enter = "jsr"
    if "interrupt" in program_doc:
        text = program_doc["interrupt"]
        if not isinstance(text, str):
            raise r.error("program.interrupt", f"expected \"irq\" or \"nmi\", got {describe(text)}")
        enter = r.choice(text.strip(), "program.interrupt", ENTRY_KINDS, fold_case=True)
    exits = _exits(r, program, program_doc.get("exit")) if "exit" in program_doc else ()
    mocks = tuple(_mock(r, program, name, value, seconds, load_function)
                  for name, value in r.table(doc.get("mocks", {}), "mocks").items())
    hardware = tuple(_hardware(r, program, name, value, seconds, load_function, cpu)
                     for name, value in r.table(doc.get("hardware", {}), "hardware").items())
    _distinct(r, mocks, hardware, exits, program)
    return World(mocks, hardware, enter, exits)


def _exits(r: Fields, program: Program, value) -> tuple[int, ...]:
    items = value if isinstance(value, list) else [value]
    if not items or not all(isinstance(v, (str, int)) and not isinstance(v, bool) for v in items):
        raise r.error("program.exit", f"expected a label or an address (or a list of them), got {describe(value)}")
    return tuple(dict.fromkeys(resolve(r, program, str(v), "program.exit") for v in items))


def _one_address(r: Fields, program: Program, doc: dict, key: str) -> int:
    r.required(doc, "at", key)
    if isinstance(doc["at"], list):
        raise r.error(f"{key}.at", "expected one label or address")
    (place,) = places_of(r, program, doc["at"], None, f"{key}.at")
    if place.kind != "memory":
        raise r.error(f"{key}.at", "expected a label or an address, not a register or flag")
    return place.address


def _function(r: Fields, doc: dict, key: str, seconds: int, load_function: Callable,
              allowed: tuple[str, ...]) -> tuple[Callable, tuple[str, ...]]:
    text = doc["function"]
    function = load_function(text if isinstance(text, str) else None, r, f"{key}.function", seconds)
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return function, allowed
    if any(p.kind == inspect.Parameter.VAR_KEYWORD for p in parameters.values()):
        return function, allowed
    for name, parameter in parameters.items():
        if name not in allowed and parameter.default is inspect.Parameter.empty:
            raise r.error(f"{key}.function", f"{text} needs argument {name!r}; it is given any of {', '.join(allowed)}")
    return function, tuple(n for n in allowed if n in parameters)


def _bit(r: Fields, value, key: str) -> int:
    if isinstance(value, bool):
        return int(value)
    return r.integer(value, key, 0, 1)


def _entry(r: Fields, program: Program, key: str, doc, known: set[str], shape: str) -> int:
    """A `[mocks]` or `[hardware]` entry's name and table checked; its address."""
    if not key.partition(".")[2].isidentifier() or key.partition(".")[2].startswith("__"):
        raise r.error(key, "a name must be a Python identifier (the reference may take a mock's calls by name)")
    if not isinstance(doc, dict):
        raise r.error(key, f"expected a table {shape}")
    r.known(doc, key, known)
    return _one_address(r, program, doc, key)


def _mock(r: Fields, program: Program, name: str, doc, seconds: int, load_function: Callable) -> Mock:
    key = f"mocks.{name}"
    address = _entry(r, program, key, doc, MOCK_KEYS,
                     "{ at = ..., cycles = N, A = ..., C = ..., writes = {...}, args = [...] }")
    if program.origin <= address < program.end:
        raise r.error(f"{key}.at", f"${address:04X} is inside the program (${program.origin:04X}-"
                                   f"${program.end - 1:04X}): a JSR there runs the program's code; mock only "
                                   "what lies outside it")
    cycles = r.integer(r.required(doc, "cycles", key, "the cycles one call costs, from its first cycle "
                                                      "through its RTS (the caller's JSR not included)"),
                       f"{key}.cycles", 1, MAX_MOCK_CYCLES)
    registers = tuple((reg.lower(), r.byte(doc[reg], f"{key}.{reg}")) for reg in REGISTERS if reg in doc)
    flags_set = flags_clear = 0
    for flag, bit in FLAGS.items():
        if flag in doc:
            if _bit(r, doc[flag], f"{key}.{flag}"):
                flags_set |= bit
            else:
                flags_clear |= bit
    writes = ()
    if "writes" in doc:
        table = r.table(doc["writes"], f"{key}.writes")
        writes = tuple((resolve(r, program, target, f"{key}.writes.{target}"),
                        r.byte(value, f"{key}.writes.{target}")) for target, value in table.items())
    args: tuple = ()
    if "args" in doc:
        items = r.array(doc["args"], f"{key}.args", "registers, flags, labels or addresses")
        args = tuple((str(item).strip(), places_of(r, program, item, None, f"{key}.args[{i}]")[0])
                     for i, item in enumerate(items))
        if len({text for text, _ in args}) != len(args):
            raise r.error(f"{key}.args", "a place is named twice")
    function, parameters = None, ()
    if "function" in doc:
        stated = sorted(k for k in doc if k in (*REGISTERS, *FLAGS, "writes"))
        if stated:
            raise r.error(f"{key}.function", f"a function mock says its effects itself: drop {', '.join(stated)}")
        function, parameters = _function(r, doc, key, seconds, load_function, FUNCTION_MOCK_ARGUMENTS)
    return Mock(name, address, cycles, registers, flags_set, flags_clear, writes, args, function, parameters)


def _read_modify_write_of(program: Program, address: int, cpu: str) -> int | None:
    """Where the program's bytes hold an NMOS read-modify-write of `address` (INC $D020: it writes the
    old value, then the new one), or None. Data bytes that look like one only cost the batched core."""
    if VARIANTS[cpu].opcode_table is not VARIANTS["6510"].opcode_table:
        return None  # the 65C02 writes once
    table, code = VARIANTS[cpu].opcode_table, program.code
    for i in range(len(code) - 2):
        row = table[code[i]]
        if row.mnemonic in RMW_MNEMONICS and row.mode in ("abs", "abx", "aby") and (code[i + 1] | code[i + 2] << 8) == address:
            return program.origin + i
    return None


def _hardware(r: Fields, program: Program, name: str, doc, seconds: int, load_function: Callable,
              cpu: str = "6510") -> Hardware:
    key = f"hardware.{name}"
    address = _entry(r, program, key, doc, HARDWARE_KEYS, "{ at = ..., reads = [...] | function = \"FILE.py:NAME\" }")
    if address < FIRST_DEVICE_ADDRESS:
        raise r.error(f"{key}.at", f"${address:04X} is in zero page or the stack, which are RAM only here "
                                   "(their accesses are not timed per bus cycle)")
    if program.origin <= address < program.end:
        raise r.error(f"{key}.at", f"${address:04X} is inside the program (${program.origin:04X}-${program.end - 1:04X})")
    if "reads" in doc and "function" in doc:
        raise r.error(key, "give reads or function, not both")
    if "reads" in doc:
        value = doc["reads"]
        if isinstance(value, list) and not value:
            raise r.error(f"{key}.reads", "the list of values is empty")
        reads = tuple(r.byte_list(value, f"{key}.reads", most=MAX_READS_LISTED)) if isinstance(value, list) else None
        if reads is None:
            raise r.error(f"{key}.reads", f"expected a list of bytes, got {describe(value)}")
        return Hardware(name, address, reads, rmw_at=_read_modify_write_of(program, address, cpu))
    if "function" in doc:
        function, parameters = _function(r, doc, key, seconds, load_function, HARDWARE_FUNCTION_ARGUMENTS)
        return Hardware(name, address, None, function, parameters)
    return Hardware(name, address, rmw_at=_read_modify_write_of(program, address, cpu))


def _distinct(r: Fields, mocks: tuple[Mock, ...], hardware: tuple[Hardware, ...], exits: tuple[int, ...],
              program: Program) -> None:
    owner: dict[int, str] = {}
    for key, address in ([(f"mocks.{m.name}.at", m.address) for m in mocks]
                         + [(f"hardware.{h.name}.at", h.address) for h in hardware]
                         + [("program.exit", e) for e in exits]):
        if address in owner:
            raise r.error(key, f"${address:04X} is also {owner[address]}")
        owner[address] = key.removesuffix(".at")


def check_names(r: Fields, world: World, inputs: tuple[Port, ...], memory: tuple) -> None:
    """A mock's name is what the reference takes its calls by: it may not be an input's or a block's.
    An input or a memory block on a hardware address would be hidden by its script: an error."""
    taken = {p.name: "inputs" for p in inputs} | {block.name: "memory" for block in memory}
    for mock in world.mocks:
        if mock.name in taken:
            raise r.error(f"mocks.{mock.name}", f"{taken[mock.name]}.{mock.name} has the same name (the reference "
                                                "takes both by name)")
    for hardware in world.hardware:
        for port in inputs:
            if any(p.kind == "memory" and p.address == hardware.address for p in port.places):
                raise r.error(f"inputs.{port.name}.at", f"${hardware.address:04X} is hardware.{hardware.name}: its "
                                                        "reads come from the script, not from the input")
        for block in memory:
            if block.address <= hardware.address < block.address + max(block.size, 1):
                raise r.error(f"memory.{block.name}.at", f"${hardware.address:04X} is hardware.{hardware.name}: its "
                                                         "reads come from the script, not from the block")


def world_output(r: Fields, world: World, name: str, doc: dict) -> Port:
    """An output of the world: `{ calls = MOCK }` (how many calls), `{ writes = HARDWARE }` (how
    many writes) or `{ writes = HARDWARE, size = N }` (the first N values written, 0 for those not)."""
    key = f"outputs.{name}"
    if not name.isidentifier() or name.startswith("__"):
        raise r.error(key, "a name must be a Python identifier (it names the reference's argument)")
    r.known(doc, key, OUTPUT_KEYS)
    kind = r.exactly_one(doc, ("calls", "writes"), key)
    target = doc[kind]
    names = [m.name for m in world.mocks] if kind == "calls" else [h.name for h in world.hardware]
    if not isinstance(target, str) or target not in names:
        section = "mocks" if kind == "calls" else "hardware"
        raise r.error(f"{key}.{kind}", f"expected the name of a [{section}] entry ({', '.join(names) or 'none'}), "
                                       f"got {describe(target)}")
    if "size" in doc:
        if kind == "calls":
            raise r.error(f"{key}.size", "a calls output is a count: it takes no size")
        size = r.integer(doc["size"], f"{key}.size", 1, MAX_WRITES_OUTPUT)
        return Port(name, tuple(Place("written", register=target, bit=k) for k in range(size)), table=True)
    return Port(name, tuple(Place("count", register=f"{kind}:{target}", bit=k) for k in range(COUNT_PLACES)))


def is_world_output(value) -> bool:
    return isinstance(value, dict) and ("calls" in value or "writes" in value)


def recorded_mocks(world: World, parameters: set[str], takes_any: bool) -> World:
    """The world with the mocks whose calls the reference takes by name marked as recorded."""
    names = frozenset(m.name for m in world.mocks if m.name in parameters or takes_any)
    return World(world.mocks, world.hardware, world.enter, world.exits, names)


def reference_calls(world: World) -> tuple[str, ...]:
    return tuple(m.name for m in world.mocks if m.name in world.recorded)


# ---- on Machine -----------------------------------------------------------------------------------

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


def function_effects(mock: Mock, state: dict, spec: str) -> tuple[list, int, int, list]:
    """A function mock called with the machine `state` it names: its effects, checked, as (registers,
    flags set, flags cleared, writes); the same on both engines (a one-line error for nonsense)."""
    count = state["count"]
    where = f"{spec}: mocks.{mock.name}.function"
    result = _call_user(mock.function, mock.parameters, state, where, f"call {count}")
    registers, flags_set, flags_clear, writes = [], 0, 0, []
    if result is None:
        return registers, flags_set, flags_clear, writes
    if not isinstance(result, dict) or not set(result) <= _RESULT_KEYS:
        raise InputError(f"{where} returned {shown(result)} (call {count}): expected None or a dict with keys "
                         f"among {', '.join(sorted(_RESULT_KEYS))}")
    for key, value in result.items():
        if key == "writes":
            if not isinstance(value, dict):
                raise InputError(f"{where} returned writes = {shown(value)} (call {count}): expected {{address: byte}}")
            writes = [(_whole(address, 0xFFFF, where, count), _whole(byte, 0xFF, where, count))
                      for address, byte in value.items()]
        elif key in FLAGS:
            if _whole(value, 1, where, count):
                flags_set |= FLAGS[key]
            else:
                flags_clear |= FLAGS[key]
        else:
            registers.append((key.lower(), _whole(value, 0xFF, where, count)))
    return registers, flags_set, flags_clear, writes


def _call_user(function: Callable, parameters: tuple[str, ...], state: dict, where: str, which: str):
    """A spec's function (already under the sandbox's guards) called with the state it names; whatever
    it raises is one line naming it and the call or read."""
    try:
        return function(**{name: state[name] for name in parameters})
    except UserCodeError:
        raise
    except Exception as exc:
        raise InputError(f"{where} raised {type(exc).__name__}: {str(exc)[:200]} ({which})") from None


def _whole(value, most: int, where: str, count: int) -> int:
    if isinstance(value, bool):
        value = int(value)
    if isinstance(value, np.integer):
        value = int(value)
    if not isinstance(value, int) or not 0 <= value <= most:
        raise InputError(f"{where} returned {shown(value)} (call {count}): expected a whole number 0..{most}")
    return value


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
        value = _call_user(hardware.function, hardware.parameters, state, where, f"read {count}")
        return _whole(value, 0xFF, where, count)

    def write(self, address: int, value: int, cycle: int) -> None:
        written = self.world.written[self.hardware.name]
        if len(written) >= MAX_RECORDED:
            raise RunError(f"hardware {self.hardware.name} (${address:04X}) was written more than "
                           f"{MAX_RECORDED:,} times in one call")
        written.append(value)
        self.memory[address] = value

    def peek(self, address: int) -> int:
        return self.memory[address]


# ---- on the batched core ------------------------------------------------------------------------------

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


# ---- a scene's chips ---------------------------------------------------------------------------------

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
