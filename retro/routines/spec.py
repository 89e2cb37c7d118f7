"""Routine specs: one TOML file describes one routine completely (docs/specs.md lists every key).

`load_spec(path)` validates the file into a `Routine`: the program (file, symbols, entry, CPU,
init), its inputs and outputs (where each value lives: register, flag or memory), the memory it reads
besides its inputs, the reference function, the cases (exhaustive, random, boundary lists, sweeps,
the `where` domain) and the cycle budget and loop bounds. The seven built-in routines are spec files
in asm/ read by this same code.

Locations are resolved against the program's symbols when the spec is loaded, so an unknown label
is an error naming the key (`boxhit.toml: inputs.bx.at: unknown label 'box_b'`), never a late
failure in a worker.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path


from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_V, FLAG_Z, VARIANTS
from retro.machines import BARE, MACHINE_CPUS, MACHINES, machine_for
from retro.errors import InputError
from retro.fields import Fields, describe
from retro.fileio import cached_reads, is_dir, note_input, parse_toml, read_bytes
from retro.loaders import load_program
from retro.program import Program
from retro.routines.rows import Row, misplaced_rows, parse_rows
from retro.routines import sandbox
from retro.routines.where import Condition, parse_where

BYTE_VALUES = 256
MAX_EXHAUSTIVE = 1 << 32  # cases in an exhaustive set
MAX_RANDOM = 10 ** 9
DEFAULT_RANDOM = 10_000  # random cases when a spec does not say (2,000 of them without --exhaustive)
MAX_TABLE = 0x10000
MAX_SPEC_BYTES = 1 << 20  # a spec file is a page of TOML, never megabytes
MAX_LOOP_BOUND = 1 << 20
NUMBER_CHARACTERS = 40  # the longest number a spec may write as text
REGISTERS = ("A", "X", "Y")
FLAGS = {"C": FLAG_C, "Z": FLAG_Z, "I": FLAG_I, "D": FLAG_D, "V": FLAG_V, "N": FLAG_N}
CPUS = tuple(VARIANTS)

TOP_KEYS = {"name", "summary", "program", "inputs", "outputs", "memory", "reference", "cases", "cycles", "rows"}
PROGRAM_KEYS = {"file", "symbols", "entry", "cpu", "machine", "init", "load"}
PORT_KEYS = {"at", "size", "values", "table"}
MEMORY_KEYS = {"at", "bytes", "file", "generator", "values", "size", "fill", "skip"}
REFERENCE_KEYS = {"function", "arrays", "time_limit"}
CASES_KEYS = {"exhaustive", "random", "seed", "where", "boundary", "sweep", "random_generator", "coverage"}
CYCLES_KEYS = {"max", "loops", "limit", "static"}

_LABEL = re.compile(r"^(?P<name>[A-Za-z_@.][\w.:@]*)\s*(?:(?P<sign>[+-])\s*(?P<offset>\S+))?$")


# ---- plain data ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class Place:
    """Where one byte (or one flag bit) of a value lives."""

    kind: str  # "register" (A/X/Y), "flag" (a P bit) or "memory"
    register: str = ""  # "a", "x", "y" for registers
    bit: int = 0  # the P bit for flags
    address: int = 0  # for memory

    def describe(self) -> str:
        if self.kind == "register":
            return self.register.upper()
        if self.kind == "flag":
            return next(name for name, bit in FLAGS.items() if bit == self.bit)
        return f"${self.address:04X}"


@dataclass(frozen=True)
class Values:
    """The values an input (or each byte of a table input) takes: lo..hi, or a list."""

    lo: int
    hi: int
    listed: tuple[int, ...] | None = None

    @property
    def count(self) -> int:
        return len(self.listed) if self.listed is not None else self.hi - self.lo + 1

    def at(self, index: int) -> int:
        return self.listed[index] if self.listed is not None else self.lo + index

    def describe(self) -> str:
        if self.listed is not None:
            return "[" + ", ".join(str(v) for v in self.listed[:8]) + (", ..." if len(self.listed) > 8 else "") + "]"
        return f"{self.lo}..{self.hi}"


@dataclass(frozen=True)
class Port:
    """An input or an output: a number over one or more byte places (low byte first), or a table."""

    name: str
    places: tuple[Place, ...]
    table: bool = False  # a list of bytes at consecutive addresses, not one number
    values: Values | None = None  # inputs only: per value (per byte for a table)

    @property
    def flag(self) -> bool:
        return self.places[0].kind == "flag"

    @property
    def bits(self) -> int:
        return 1 if self.flag else 8 * (1 if self.table else len(self.places))

    @property
    def count(self) -> int:
        """How many distinct values the input takes (a table: per byte, to the power of its size)."""
        return self.values.count ** len(self.places) if self.table else self.values.count

    def describe(self) -> str:
        if self.table:
            return f"{len(self.places)} bytes at {self.places[0].describe()}"
        return "+".join(p.describe() for p in self.places)


@dataclass(frozen=True)
class MemoryBlock:
    """Memory the routine reads besides its inputs, set once before the cases (after `init`)."""

    name: str
    address: int
    data: tuple[int, ...] | None  # fixed bytes; None when made by `make` from the seed
    make: Callable | None = None  # (rng) -> bytes: a generator, or random `values` of `size` bytes
    size: int = 0


@dataclass(frozen=True)
class Routine:
    name: str
    spec_path: Path
    program_file: Path
    symbols_file: Path | None
    load: int | None
    entry: str
    cpu: str
    machine: str  # "c64", "nes" or "none" (a bare CPU): what the raster figures are for
    init: str | None
    inputs: tuple[Port, ...]
    outputs: tuple[Port, ...]
    memory: tuple[MemoryBlock, ...]
    reference: Callable | None  # None: a spec of rows only
    reference_name: str
    reference_memory: tuple[str, ...]  # memory blocks the reference takes by name
    reference_arrays: bool = False  # the reference takes numpy arrays (one element per case) and answers so
    exhaustive: tuple[str, ...] = ()
    random: int = 0
    seed: int = 0
    domain: tuple[Condition, ...] = ()
    boundary: Callable | None = None
    sweep: Callable | None = None
    random_generator: Callable | None = None
    budget: int | None = None
    loop_bounds: dict[str, int] = field(default_factory=dict)
    limit: int | None = None  # cycles one call may take before it is stopped as a runaway
    static: bool = True
    summary: str = ""
    coverage: str = ""  # why the cases cover the input space (an argument the report quotes)
    notes: tuple[str, ...] = ()  # what loading the program left out (a symbol file's skipped lines)
    rows: tuple[Row, ...] = ()  # expected rows written in the spec (retro.routines.rows)

    @property
    def input_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.inputs)

    @property
    def output_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.outputs)

    def in_domain(self, case: tuple) -> bool:
        return all(condition.test(*case) for condition in self.domain)

    def input_space(self) -> int:
        """Distinct inputs: the product of every input's count of values."""
        count = 1
        for port in self.inputs:
            count *= port.count
        return count

    def exhaustive_count(self) -> int:
        count = 1
        for port in self.inputs:
            if port.name in self.exhaustive:
                count *= port.count
        return count if self.exhaustive else 0


# ---- reading a spec --------------------------------------------------------------------------------

def read_spec_document(path: str | Path) -> dict:
    shown = str(path)
    data = read_bytes(path, "routine spec")
    if len(data) > MAX_SPEC_BYTES:
        raise InputError(f"{shown}: a routine spec of {len(data)} bytes is too large (at most {MAX_SPEC_BYTES})")
    return parse_toml(data, shown)


@cached_reads(maxsize=64)  # a cached spec still names its files (program, memory, Python) as inputs
def _load_cached(resolved: str, shown: str, mtime: float) -> Routine:
    return parse_spec(read_spec_document(resolved), Path(resolved), shown)


def load_spec(path: str | Path) -> Routine:
    """Read and validate a routine spec; cached while the file is unchanged."""
    spec_path = Path(path)
    try:
        mtime = spec_path.stat().st_mtime
    except OSError:
        read_bytes(spec_path, "routine spec")  # raises the one-line error
        raise
    if is_dir(spec_path):
        raise InputError(f"{path}: is a folder, not a routine spec")
    return _load_cached(str(spec_path.resolve()), str(path), mtime)


def _machine(r: Fields, program_doc: dict, cpu: str) -> str:
    """`program.machine`: the machine the routine runs in (default: the CPU's, retro.machines.machine_for)."""
    name = _text(r, program_doc, "machine", "program.machine")
    if name is None:
        return machine_for(cpu)
    name = r.choice(name, "program.machine", MACHINES, fold_case=True)
    if name != BARE and MACHINE_CPUS[name] != cpu:
        raise r.error("program.machine", f"the {name.upper()} has a {MACHINE_CPUS[name].upper()}, not the "
                                         f"{cpu.upper()} the program runs on (program.cpu, or the file's own CPU)")
    return name


def parse_spec(doc: dict, path: Path, shown: str | None = None) -> Routine:
    r = Fields(shown or str(path), folder=path.parent, number_characters=NUMBER_CHARACTERS)
    r.table(doc, "", TOP_KEYS)
    misplaced_rows(r, doc)
    seconds = sandbox.time_limit(r, r.table(doc.get("reference", {}), "reference"), "reference")
    program_doc = r.table(r.required(doc, "program", hint="the [program] table"), "program", PROGRAM_KEYS)
    program_file = r.file(_text(r, program_doc, "file", "program.file", required=True), "program.file", resolve=True)
    symbols_name = _text(r, program_doc, "symbols", "program.symbols")
    symbols_file = r.file(symbols_name, "program.symbols", resolve=True) if symbols_name else None
    load = r.integer(program_doc["load"], "program.load", 0, 0xFFFF) if "load" in program_doc else None
    cpu = _text(r, program_doc, "cpu", "program.cpu")
    if cpu is not None:
        cpu = r.choice(cpu, "program.cpu", CPUS, fold_case=True)
    try:
        program = load_program(program_file, symbols=symbols_file, load=load, cpu=cpu)
    except InputError as exc:  # named by the key that named the file
        field = "program.symbols" if symbols_file and str(exc).startswith(str(symbols_file)) else "program.file"
        raise r.error(field, str(exc)) from None
    if cpu is not None and program.cpu is not None and cpu != program.cpu:
        raise r.error("program.cpu", f"{program_file.name} is a program for the {program.cpu.upper()}, "
                                     f"not the {cpu.upper()}")
    cpu = cpu or program.cpu or "6510"
    machine = _machine(r, program_doc, cpu)
    entry = _entry_text(r, program_doc, "entry", required=True)
    init = _entry_text(r, program_doc, "init")
    for field_name, text in (("program.entry", entry), ("program.init", init)):
        if text is not None:
            _in_program(r, program, _resolve(r, program, text, field_name), field_name)

    inputs = tuple(_port(r, program, name, value, "inputs", is_input=True)
                   for name, value in r.table(r.required(doc, "inputs", hint="the [inputs] table"), "inputs").items())
    outputs = tuple(_port(r, program, name, value, "outputs", is_input=False)
                    for name, value in r.table(r.required(doc, "outputs", hint="the [outputs] table"),
                                               "outputs").items())
    if not outputs:
        raise r.error("outputs", "names no output")
    _no_overlap(r, inputs, "inputs")
    memory = tuple(_memory_block(r, program, name, value, seconds)
                   for name, value in r.table(doc.get("memory", {}), "memory").items())
    _no_overlap_memory(r, memory, inputs)

    rows = parse_rows(r, doc["rows"], inputs, outputs) if "rows" in doc else ()
    if rows and "reference" not in doc:  # a spec of rows only: the rows say what the routine must answer
        if "cases" in doc:
            raise r.error("cases", "without a [reference] no answer is known for generated cases: write them as rows, "
                                   "or add a [reference]")
        reference, reference_name, reference_memory, reference_arrays = None, "", (), False
    else:
        reference_doc = r.table(r.required(doc, "reference", hint="the [reference] table, or [[rows]]"), "reference",
                                REFERENCE_KEYS)
        reference_name = _text(r, reference_doc, "function", "reference.function", required=True)
        reference = load_function(reference_name, r, "reference.function", seconds, faults_only=True)
        reference_memory = _reference_signature(r, reference, reference_name, inputs, memory)
        # true: the function takes numpy arrays, one element per case
        reference_arrays = r.flag(reference_doc.get("arrays", False), "reference.arrays")

    cases_doc = r.table(doc.get("cases", {}), "cases", CASES_KEYS)
    names = tuple(p.name for p in inputs)
    exhaustive = cases_doc.get("exhaustive", [])
    if not isinstance(exhaustive, list) or not all(isinstance(n, str) for n in exhaustive):
        raise r.error("cases.exhaustive", "expected a list of input names")
    for n in exhaustive:
        if n not in names:
            raise r.error("cases.exhaustive", f"unknown input {n!r} (inputs: {', '.join(names)})")
    if len(set(exhaustive)) != len(exhaustive):
        raise r.error("cases.exhaustive", "an input is named twice")
    random_default = DEFAULT_RANDOM if reference is not None else 0  # rows only: no generated cases
    random_count = r.integer(cases_doc.get("random", random_default), "cases.random", 0, MAX_RANDOM)
    seed = r.integer(cases_doc.get("seed", 0), "cases.seed", 0, 2 ** 63 - 1)
    where = cases_doc.get("where")
    coverage = _text(r, cases_doc, "coverage", "cases.coverage") or ""
    tables = frozenset(p.name for p in inputs if p.table)
    bounds = {p.name: (p.values.lo, p.values.hi) for p in inputs if not p.table}  # what int64 columns must hold
    domain = parse_where(where, names, f"{r.source}: cases.where", tables, bounds) if where is not None else ()
    generators = {key: load_function(_text(r, cases_doc, key, f"cases.{key}"), r, f"cases.{key}", seconds)
                  for key in ("boundary", "sweep", "random_generator") if key in cases_doc}

    cycles_doc = r.table(doc.get("cycles", {}), "cycles", CYCLES_KEYS)
    budget = r.integer(cycles_doc["max"], "cycles.max", 1, 1 << 40) if "max" in cycles_doc else None
    limit = r.integer(cycles_doc["limit"], "cycles.limit", 1, 1 << 40) if "limit" in cycles_doc else None
    loops_doc = r.table(cycles_doc.get("loops", {}), "cycles.loops")  # label = bound, e.g. { loop = 8 }
    loop_bounds = {}
    for label, bound in loops_doc.items():
        _resolve(r, program, label, f"cycles.loops.{label}")
        loop_bounds[label] = r.integer(bound, f"cycles.loops.{label}", 1, MAX_LOOP_BOUND)
    static = r.flag(cycles_doc.get("static", True), "cycles.static")

    name = _text(r, doc, "name", "name") or path.stem
    summary = doc.get("summary", "")
    if not isinstance(summary, str):
        raise r.error("summary", f"expected a string, got {describe(summary)}")
    routine = Routine(
        name=name, spec_path=path, program_file=program_file, symbols_file=symbols_file, load=load, entry=entry,
        cpu=cpu, machine=machine, init=init, inputs=inputs, outputs=outputs, memory=memory, reference=reference,
        reference_name=reference_name, reference_memory=reference_memory, reference_arrays=reference_arrays, exhaustive=tuple(exhaustive),
        random=random_count, seed=seed, domain=domain, boundary=generators.get("boundary"),
        sweep=generators.get("sweep"), random_generator=generators.get("random_generator"), budget=budget,
        loop_bounds=loop_bounds, limit=limit, static=static, summary=summary, coverage=coverage, rows=rows,
        notes=program.notes)
    if not (routine.random or routine.exhaustive or routine.boundary or routine.sweep or routine.rows):
        raise r.error("cases", "no cases: give random = N, exhaustive = [...], boundary, sweep or [[rows]]")
    if routine.exhaustive_count() > MAX_EXHAUSTIVE:
        raise r.error("cases.exhaustive", f"{routine.exhaustive_count():,} cases is more than 2^32: "
                                         "narrow the inputs' values or sweep fewer inputs")
    return routine


def _text(r: Fields, doc: dict, key: str, field: str, required: bool = False) -> str | None:
    """doc[key] as a string without its surrounding spaces; None when it is absent and not required."""
    if key not in doc and not required:
        return None
    return r.string(r.required(doc, key, field.rpartition(".")[0]), field).strip()


def _entry_text(r: Fields, doc: dict, key: str, required: bool = False) -> str | None:
    if key not in doc:
        if required:
            r.required(doc, key, "program", "a label or an address")
        return None
    value = doc[key]
    if isinstance(value, int) and not isinstance(value, bool):
        return str(r.integer(value, f"program.{key}", 0, 0xFFFF))
    return _text(r, doc, key, f"program.{key}")


def _in_program(r: Fields, program: Program, address: int, field_name: str) -> None:
    """A routine starts in the program's bytes: elsewhere the 6502 would run zeroed RAM."""
    if not program.origin <= address < program.end:
        raise r.error(field_name, f"${address:04X} is outside the program (${program.origin:04X}-${program.end - 1:04X})")


def _resolve(r: Fields, program: Program, text: str, field_name: str) -> int:
    """A label (optionally `label+N`) of the program, or an address."""
    text = str(text).strip()
    if text in program.symbols:
        return program.symbols[text]
    if text in program.ambiguous:
        from retro.program import ambiguity_message

        raise r.error(field_name, ambiguity_message(text, program.ambiguous[text]))
    if text[:1] in "$%" or text[:1].isdigit():
        return r.integer(text, field_name, 0, 0xFFFF)
    match = _LABEL.match(text)
    if match and match.group("sign"):
        base = _resolve(r, program, match.group("name"), field_name)
        offset = r.integer(match.group("offset"), field_name, 0, 0xFFFF)
        address = base + offset if match.group("sign") == "+" else base - offset
        if not 0 <= address <= 0xFFFF:
            raise r.error(field_name, f"{text} is outside $0000-$FFFF")
        return address
    hint = " (registers are written A, X, Y and flags C, Z, I, D, V, N)" if text.upper() in (*REGISTERS, *FLAGS) else ""
    if not program.symbols:
        hint = f" ({program.source or 'the program'} has no symbols: give [program] symbols, or an address)"
    raise r.error(field_name, f"unknown label {text!r}{hint}")


def _places(r: Fields, program: Program, at, size: int | None, key: str) -> tuple[Place, ...]:
    items = at if isinstance(at, list) else [at]
    if not items:
        raise r.error(key, "expected a register, flag, label or address")
    places: list[Place] = []
    for item in items:
        if isinstance(item, int) and not isinstance(item, bool):
            item = str(item)
        if not isinstance(item, str) or not item.strip():
            raise r.error(key, f"expected a register, flag, label or address, got {item!r:.40}")
        text = item.strip()
        if text in REGISTERS:
            places.append(Place("register", register=text.lower()))
        elif text in FLAGS:
            places.append(Place("flag", bit=FLAGS[text]))
        else:
            places.append(Place("memory", address=_resolve(r, program, text, key)))
    if size is not None:
        if len(places) != 1 or places[0].kind != "memory":
            raise r.error(key, "size goes with one memory location (a label or an address)")
        start = places[0].address
        if start + size > 0x10000:
            raise r.error(key, f"{size} bytes from ${start:04X} run past $FFFF")
        places = [Place("memory", address=start + i) for i in range(size)]
    if any(p.kind == "flag" for p in places) and len(places) > 1:
        raise r.error(key, "a flag is one bit: it cannot be combined with other places")
    return tuple(places)


def parse_values(r: Fields, value, key: str) -> Values:
    if isinstance(value, str):
        lo_text, sep, hi_text = value.partition("..")
        if not sep:
            raise r.error(key, f"expected a range LO..HI or a list, got {value!r:.40}")
        lo = r.integer(lo_text.strip(), key, 0, (1 << 32) - 1)
        hi = r.integer(hi_text.strip(), key, 0, (1 << 32) - 1)
        if hi < lo:
            raise r.error(key, f"empty range {value!r}")
        return Values(lo, hi)
    if isinstance(value, list):
        if not value:
            raise r.error(key, "the list of values is empty")
        if len(value) > MAX_TABLE:
            raise r.error(key, f"more than {MAX_TABLE} listed values")
        listed = tuple(dict.fromkeys(r.integer(v, key, 0, (1 << 32) - 1) for v in value))
        return Values(min(listed), max(listed), listed)
    raise r.error(key, f"expected a range \"LO..HI\" or a list of numbers, got {describe(value)}")


def _port(r: Fields, program: Program, name: str, value, section: str, is_input: bool) -> Port:
    key = f"{section}.{name}"
    if not name.isidentifier() or name.startswith("__"):
        raise r.error(key, "a name must be a Python identifier (it names the reference's argument)")
    doc = {"at": value} if isinstance(value, (str, list)) else value
    if not isinstance(doc, dict):
        raise r.error(key, "expected a location (\"A\", \"C\", \"label\", \"$fb\") or a table { at = ... }")
    r.known(doc, key, PORT_KEYS if is_input else PORT_KEYS - {"values"})
    r.required(doc, "at", key)
    size = r.integer(doc["size"], f"{key}.size", 1, MAX_TABLE) if "size" in doc else None
    places = _places(r, program, doc["at"], size, f"{key}.at")
    values = parse_values(r, doc["values"], f"{key}.values") if "values" in doc else None
    table_flag = r.flag(doc["table"], f"{key}.table") if "table" in doc else None
    # `size` N with byte values is a table of N bytes; otherwise an N-byte little-endian number
    table = table_flag if table_flag is not None else (
        size is not None and size > 1 and values is not None and values.hi < BYTE_VALUES)
    if table and (size is None or places[0].kind != "memory"):
        raise r.error(f"{key}.table", "a table needs a memory location and a size")
    port = Port(name, places, table, None)
    width = 1 << port.bits
    if values is None and is_input:
        values = Values(0, (BYTE_VALUES if table else width) - 1)
    if values is not None:
        limit = BYTE_VALUES if table else width
        if values.hi >= limit:
            raise r.error(f"{key}.values", f"{values.describe()} does not fit in {port.describe()} "
                                          f"({'each byte ' if table else ''}0..{limit - 1})")
    return Port(name, places, table, values)


def _no_overlap(r: Fields, ports: tuple[Port, ...], section: str) -> None:
    owner: dict[Place, str] = {}
    for port in ports:
        for place in port.places:
            if place in owner:
                raise r.error(f"{section}.{port.name}.at",
                              f"{place.describe()} is also where {section}.{owner[place]} goes")
            owner[place] = port.name


def _memory_block(r: Fields, program: Program, name: str, doc, seconds: int = sandbox.DEFAULT_SECONDS) -> MemoryBlock:
    key = f"memory.{name}"
    if not name.isidentifier():
        raise r.error(key, "a name must be a Python identifier (the reference may take it by name)")
    if not isinstance(doc, dict):
        raise r.error(key, "expected a table { at = ..., bytes = [...] | file = ... | generator = ... | values + size }")
    r.known(doc, key, MEMORY_KEYS)
    r.required(doc, "at", key)
    (place,) = _places(r, program, doc["at"], None, f"{key}.at")[:1] or (None,)
    if place is None or place.kind != "memory" or isinstance(doc["at"], list):
        raise r.error(f"{key}.at", "expected one label or address")
    source = r.exactly_one(doc, ("bytes", "file", "generator", "values", "fill"), key)
    address = place.address
    if source == "bytes":
        data = _byte_list(r, doc["bytes"], f"{key}.bytes")
    elif source == "file":
        raw = read_bytes(r.file(doc["file"], f"{key}.file", resolve=True), f"{key}.file")
        skip = r.integer(doc.get("skip", 0), f"{key}.skip", 0, len(raw))
        data = tuple(raw[skip:])
        if "size" in doc:
            data = data[:r.integer(doc["size"], f"{key}.size", 0, MAX_TABLE)]
    elif source == "fill":
        size = r.integer(r.required(doc, "size", key), f"{key}.size", 1, MAX_TABLE)
        data = (r.integer(doc["fill"], f"{key}.fill", 0, 0xFF),) * size
    else:
        data = None
    if data is not None:
        _fits(r, key, address, len(data))
        return MemoryBlock(name, address, data, None, len(data))
    if source == "values":
        size = r.integer(r.required(doc, "size", key), f"{key}.size", 1, MAX_TABLE)
        values = parse_values(r, doc["values"], f"{key}.values")
        if values.hi >= BYTE_VALUES:
            raise r.error(f"{key}.values", "memory bytes are 0..255")
        _fits(r, key, address, size)

        def make(rng, _values=values, _size=size):
            if _values.listed is not None:
                return rng.choice(list(_values.listed), size=_size)
            return rng.integers(_values.lo, _values.hi + 1, size=_size)
        return MemoryBlock(name, address, None, make, size)
    function = load_function(doc["generator"] if isinstance(doc["generator"], str) else None, r, f"{key}.generator",
                             seconds)
    return MemoryBlock(name, address, None, function, 0)


def _fits(r: Fields, key: str, address: int, size: int) -> None:
    if address + size > 0x10000:
        raise r.error(key, f"{size} bytes from ${address:04X} run past $FFFF")


def _byte_list(r: Fields, value, key: str) -> tuple[int, ...]:
    """A list of bytes, or a string of hex bytes ("a9 00 60", "$a9,$00")."""
    if isinstance(value, str):
        parts = value.replace(",", " ").split()
        if len(parts) > MAX_TABLE:
            raise r.error(key, f"more than {MAX_TABLE} bytes")
        return tuple(r.byte(p if p[:1] in "$%" or p.lower().startswith("0x") else f"${p}", f"{key}[{i}]")
                     for i, p in enumerate(parts))
    return tuple(r.byte_list(value, key, most=MAX_TABLE))


def _no_overlap_memory(r: Fields, memory: tuple[MemoryBlock, ...], inputs: tuple[Port, ...]) -> None:
    fixed = sorted((m.address, m.address + m.size, m.name) for m in memory if m.size)
    for (start, end, name), (next_start, _, next_name) in zip(fixed, fixed[1:]):
        if next_start < end:
            raise r.error(f"memory.{next_name}.at", f"overlaps memory.{name} (${start:04X}-${end - 1:04X})")
    for port in inputs:
        for place in port.places:
            if place.kind != "memory":
                continue
            for start, end, name in fixed:
                if start <= place.address < end:
                    raise r.error(f"inputs.{port.name}.at",
                                  f"{place.describe()} lies inside memory.{name}: an input is set for every case")


# ---- Python functions named by a spec -------------------------------------------------------------

def load_function(text: str | None, r: Fields, key: str, seconds: int = sandbox.DEFAULT_SECONDS,
                  faults_only: bool = False) -> Callable:
    """`file.py:function` (a path relative to the spec) or `package.module:function`, run under the
    sandbox's guards (retro.routines.sandbox): `seconds` per call; with `faults_only` an ordinary
    exception reaches the caller as it is (a reference refusing a case)."""
    if not text or ":" not in text:
        raise r.error(key, "expected FILE.py:FUNCTION (relative to the spec) or MODULE:FUNCTION")
    module_text, _, function_name = text.rpartition(":")
    if not function_name.isidentifier():
        raise r.error(key, f"{function_name!r} is not a function name")
    if module_text.endswith(".py"):
        module = _module_from_file(r.file(module_text, key, resolve=True), r, key, seconds)
    else:
        try:
            module = sandbox.import_guarded(lambda: importlib.import_module(module_text), module_text, seconds)
        except sandbox.UserCodeError as exc:  # sys.exit, os._exit, a hang at import time
            raise r.error(key, f"{module_text} failed to import: {exc}") from None
        except ImportError as exc:
            raise r.error(key, f"cannot import {module_text}: {exc}") from None
    function = getattr(module, function_name, None)
    if not callable(function):
        raise r.error(key, f"{module_text} has no function {function_name!r}")
    return sandbox.guarded(function, f"{r.source}: {key} {text}", seconds, faults_only=faults_only)


@cached_reads(maxsize=64)
def import_user_module(path: str, mtime: float):
    """A user's Python file as a module, imported once per (path, modification time); its folder is
    put on sys.path so that it may import its neighbours. Routine specs and method files use it."""
    note_input(path, "Python file")
    name = f"retro_user_{abs(hash(path)):x}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # pickling and dataclasses look modules up by name
    folder = str(Path(path).parent)
    if folder not in sys.path:  # the user's module may import its neighbours, as a script would
        sys.path.append(folder)
    spec.loader.exec_module(module)
    return module


def _module_from_file(path: Path, r: Fields, key: str, seconds: int = sandbox.DEFAULT_SECONDS):
    try:
        return sandbox.import_guarded(lambda: import_user_module(str(path), path.stat().st_mtime), path.name, seconds)
    except sandbox.UserCodeError as exc:  # sys.exit, os._exit, a hang at import time
        raise r.error(key, f"{path.name} failed to import: {exc}") from None
    except Exception as exc:  # the user's module failed to import: one line, whatever it raised
        line = ""
        tb = exc.__traceback__
        while tb is not None:
            if tb.tb_frame.f_code.co_filename == str(path):
                line = f" (line {tb.tb_lineno})"
            tb = tb.tb_next
        raise r.error(key, f"{path.name} failed to import{line}: {type(exc).__name__}: {exc}") from None


def _reference_signature(r: Fields, function: Callable, text: str, inputs: tuple[Port, ...],
                         memory: tuple[MemoryBlock, ...]) -> tuple[str, ...]:
    """Check the reference takes every input by name; return the memory blocks it also takes."""
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return ()
    kinds = {p.kind for p in parameters.values()}
    takes_any = inspect.Parameter.VAR_KEYWORD in kinds
    names = set(parameters)
    for port in inputs:
        if port.name not in names and not takes_any:
            raise r.error("reference.function", f"{text} takes no argument {port.name!r} (it is called with the "
                                               "inputs by name)")
    required = [p.name for p in parameters.values() if p.default is inspect.Parameter.empty
                and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    known = {port.name for port in inputs} | {m.name for m in memory}
    for name in required:
        if name not in known:
            raise r.error("reference.function", f"{text} needs argument {name!r}, which is neither in [inputs] nor "
                                               "a [memory] block")
    return tuple(m.name for m in memory if m.name in names or takes_any)


def call_with(function: Callable, available: dict) -> object:
    """Call a generator with the keyword arguments it names among `available` (rng, count, seed)."""
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return function(**available)
    if any(p.kind == inspect.Parameter.VAR_KEYWORD for p in parameters.values()):
        return function(**available)
    return function(**{k: v for k, v in available.items() if k in parameters})
