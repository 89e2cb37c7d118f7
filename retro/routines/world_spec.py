"""A routine spec's world sections read and checked (retro.routines.world holds what they make):
`[mocks]`, `[hardware]`, `[program] interrupt` and `exit`; the world's outputs (`{ calls = MOCK }`,
`{ writes = HARDWARE }`); names and addresses that may not meet. Every error names its key."""

from __future__ import annotations

import inspect
from collections.abc import Callable

from retro.cpu.bus import FIRST_DEVICE_ADDRESS
from retro.cpu.mpu import RMW_MNEMONICS
from retro.cpu.variants import VARIANTS
from retro.fields import Fields, describe
from retro.program import Program
from retro.routines.places import FLAGS, REGISTERS, Place, Port, places_of, resolve
from retro.routines.world import (
    FUNCTION_MOCK_ARGUMENTS,
    HARDWARE_FUNCTION_ARGUMENTS,
    Hardware,
    Mock,
    World,
)

ENTRY_KINDS = ("irq", "nmi")  # `[program] interrupt`: the routine is that interrupt's handler
MOCK_KEYS = {"at", "cycles", "args", "writes", "function", *REGISTERS, *FLAGS}
HARDWARE_KEYS = {"at", "reads", "function"}
OUTPUT_KEYS = {"calls", "writes", "size"}
MAX_MOCK_CYCLES = 1 << 20
MAX_READS_LISTED = 1 << 16
MAX_WRITES_OUTPUT = 256  # values of a `writes` output
COUNT_PLACES = 2  # a count output is a 16-bit number


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
    flags_set, flags_clear = _mock_flags(r, doc, key)
    writes = _mock_writes(r, program, doc["writes"], key) if "writes" in doc else ()
    args = _mock_args(r, program, doc["args"], key) if "args" in doc else ()
    function, parameters = None, ()
    if "function" in doc:
        stated = sorted(k for k in doc if k in (*REGISTERS, *FLAGS, "writes"))
        if stated:
            raise r.error(f"{key}.function", f"a function mock says its effects itself: drop {', '.join(stated)}")
        function, parameters = _function(r, doc, key, seconds, load_function, FUNCTION_MOCK_ARGUMENTS)
    return Mock(name, address, cycles, registers, flags_set, flags_clear, writes, args, function, parameters)


def _mock_flags(r: Fields, doc: dict, key: str) -> tuple[int, int]:
    """(the P bits a mock sets, those it clears) from its `C = 1`, `Z = false`, ..."""
    flags_set = flags_clear = 0
    for flag, bit in FLAGS.items():
        if flag in doc:
            if _bit(r, doc[flag], f"{key}.{flag}"):
                flags_set |= bit
            else:
                flags_clear |= bit
    return flags_set, flags_clear


def _mock_writes(r: Fields, program: Program, value, key: str) -> tuple[tuple[int, int], ...]:
    """A mock's `writes = { label = byte, ... }` -> (address, byte) pairs."""
    table = r.table(value, f"{key}.writes")
    return tuple((resolve(r, program, target, f"{key}.writes.{target}"), r.byte(byte, f"{key}.writes.{target}"))
                 for target, byte in table.items())


def _mock_args(r: Fields, program: Program, value, key: str) -> tuple[tuple[str, Place], ...]:
    """A mock's `args = [...]`: what each call records, by the spec's text, each place named once."""
    items = r.array(value, f"{key}.args", "registers, flags, labels or addresses")
    args = tuple((str(item).strip(), places_of(r, program, item, None, f"{key}.args[{i}]")[0])
                 for i, item in enumerate(items))
    if len({text for text, _ in args}) != len(args):
        raise r.error(f"{key}.args", "a place is named twice")
    return args


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
    target = _output_target(r, world, kind, doc[kind], key)
    if "size" in doc:
        if kind == "calls":
            raise r.error(f"{key}.size", "a calls output is a count: it takes no size")
        size = r.integer(doc["size"], f"{key}.size", 1, MAX_WRITES_OUTPUT)
        return Port(name, tuple(Place("written", register=target, bit=k) for k in range(size)), table=True)
    return Port(name, tuple(Place("count", register=f"{kind}:{target}", bit=k) for k in range(COUNT_PLACES)))


def _output_target(r: Fields, world: World, kind: str, target, key: str) -> str:
    """The `[mocks]` entry a calls output counts, or the `[hardware]` entry a writes output shows."""
    names = [m.name for m in world.mocks] if kind == "calls" else [h.name for h in world.hardware]
    if not isinstance(target, str) or target not in names:
        section = "mocks" if kind == "calls" else "hardware"
        raise r.error(f"{key}.{kind}", f"expected the name of a [{section}] entry ({', '.join(names) or 'none'}), "
                                       f"got {describe(target)}")
    return target


def is_world_output(value) -> bool:
    return isinstance(value, dict) and ("calls" in value or "writes" in value)

