"""Routine specs: one TOML file describes one routine completely (docs/specs.md lists every key).

`load_spec(path)` validates the file into a `Routine`: the program (file, symbols, entry, CPU,
init), its inputs and outputs (where each value lives: register, flag or memory), the memory it reads
besides its inputs, the reference function, the cases (exhaustive, random, boundary lists, sweeps,
the `where` domain) and the cycle budget and loop bounds. The built-in routines are spec files
in asm/ read by this same code.

Locations are resolved against the program's symbols when the spec is loaded, so an unknown label
is an error naming the key (`boxhit.toml: inputs.bx.at: unknown label 'box_b'`), never a late
failure in a worker.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import sys
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path


from retro.cpu.machine import ENTRY_S
from retro.cpu.variants import VARIANTS
from retro.machines import BARE, MACHINE_CPUS, MACHINES, machine_for
from retro.errors import InputError
from retro.fields import Fields, describe
from retro.fileio import cached_reads, is_dir, note_input, parse_toml, read_bytes
from retro.loaders import load_program
from retro.loaders.source_lines import SourceMap, read_source_map
from retro.program import Program
from retro.routines.places import (
    BYTE_VALUES,
    MAX_TABLE,
    Port,
    Values,
    bind_vias,
    check_fits,
    no_overlap,
    parse_values,
    places_of,
    port_of,
    resolve,
)
from retro.routines.entry import parse_entry
from retro.routines.facts import StatedFact, parse_facts
from retro.routines.rows import Row, misplaced_rows, parse_rows
from retro.routines import sandbox
from retro.routines.world import NO_WORLD, World, recorded_mocks
from retro.routines.world_spec import check_names, is_world_output, parse_world, world_output
from retro.routines.where import Condition, parse_where

MAX_EXHAUSTIVE = 1 << 32  # cases in an exhaustive set
MAX_RANDOM = 10 ** 9
DEFAULT_RANDOM = 10_000  # random cases when a spec does not say (2,000 of them without --exhaustive)
MAX_SPEC_BYTES = 1 << 20  # a spec file is a page of TOML, never megabytes
MAX_LOOP_BOUND = 1 << 20
NUMBER_CHARACTERS = 40  # the longest number a spec may write as text
CPUS = tuple(VARIANTS)

TOP_KEYS = {"name", "summary", "program", "inputs", "outputs", "memory", "reference", "cases", "cycles", "rows",
            "mocks", "hardware", "entry", "facts"}
PROGRAM_KEYS = {"file", "symbols", "entry", "cpu", "machine", "init", "load", "listing", "interrupt", "exit", "s"}
MEMORY_KEYS = {"at", "bytes", "file", "generator", "values", "size", "fill", "skip"}
REFERENCE_KEYS = {"function", "arrays", "time_limit"}
CASES_KEYS = {"exhaustive", "random", "seed", "where", "boundary", "sweep", "random_generator", "coverage", "search",
              "random_values", "random_inside"}
MAX_SEARCH = 10_000_000  # candidates of the coverage-guided search (retro.analysis.check.search)
CYCLES_KEYS = {"max", "loops", "limit", "static"}



# ---- plain data ----------------------------------------------------------------------------------

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
    program: Program | None = None  # the program, read once when the spec is loaded
    source_map: SourceMap | None = None  # [program] listing: which source line each byte came from
    entry_address: int = 0  # entry, init and the loop labels resolved against its symbols
    init_address: int | None = None
    entry_s: int = ENTRY_S  # S at entry when no input sets it ([program] s)
    loop_addresses: dict[int, int] = field(default_factory=dict)  # loop header address -> bound
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
    search: int | None = None  # [cases] search: candidates of the coverage-guided search (None: the default)
    world: World = NO_WORLD  # mocks, scripted hardware, interrupt entry, exits (retro.routines.world)
    entry_state: tuple[tuple[str, int], ...] = ()  # `[entry]`: registers and flags the caller guarantees
    # per-part values (`exhaustive = { a = "0..7" }`, `random_values = { a = "0..255" }`): input name -> Values
    exhaustive_values: tuple[tuple[str, Values], ...] = ()
    random_values: tuple[tuple[str, Values], ...] = ()
    random_inside: bool | None = None  # draw the random part inside the domain (None: when it is a small share)
    shown_path: str = ""  # the spec's path as the user gave it (reports print it; spec_path is resolved)
    facts: tuple[StatedFact, ...] = ()  # [facts]: what the spec states at addresses (retro.routines.facts)

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
        for port in self.part_inputs("exhaustive"):
            if port.name in self.exhaustive:
                count *= port.count
        return count if self.exhaustive else 0

    def part_inputs(self, part: str) -> tuple[Port, ...]:
        """The inputs with the values a part of the cases takes ("exhaustive" or "random": the spec's
        per-part values where it gives them, else each input's own)."""
        given = dict(self.exhaustive_values if part == "exhaustive" else self.random_values if part == "random" else ())
        return tuple(replace(port, values=given[port.name]) if port.name in given else port for port in self.inputs)


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
    """A spec document -> a loaded `Routine`: the program read once and every label resolved here,
    each section read by its own function below (every error names the file and the key)."""
    r = Fields(shown or str(path), folder=path.parent, number_characters=NUMBER_CHARACTERS)
    r.table(doc, "", TOP_KEYS)
    misplaced_rows(r, doc)
    seconds = sandbox.time_limit(r, r.table(doc.get("reference", {}), "reference"), "reference")
    program = _program_section(r, doc)
    world = parse_world(r, doc, program.program, seconds, load_function, program.cpu)
    inputs, outputs, memory = _places_sections(r, doc, program.program, seconds, world, program.entry_s)
    check_names(r, world, inputs, memory)
    rows = parse_rows(r, doc["rows"], inputs, outputs) if "rows" in doc else ()
    reference = _reference_section(r, doc, inputs, memory, rows, seconds, world)
    world = reference.pop("world")
    cases = _cases_section(r, doc, inputs, seconds, answered=reference["reference"] is not None)
    cycles = _cycles_section(r, doc, program.program)
    facts = parse_facts(r, doc.get("facts", {}), program.program, program.cpu)
    routine = Routine(name=_text(r, doc, "name", "name") or path.stem, spec_path=path, **program.fields(),
                      inputs=inputs, outputs=outputs, memory=memory, **reference, **cases, **cycles,
                      summary=_summary(r, doc), rows=rows, notes=program.program.notes, world=world,
                      entry_state=parse_entry(r, doc.get("entry", {}), inputs), shown_path=shown or str(path),
                      facts=facts)
    if not (routine.random or routine.exhaustive or routine.boundary or routine.sweep or routine.rows):
        raise r.error("cases", "no cases: give random = N, exhaustive = [...], boundary, sweep or [[rows]]")
    if routine.exhaustive_count() > MAX_EXHAUSTIVE:
        raise r.error("cases.exhaustive", f"{routine.exhaustive_count():,} cases is more than 2^32: "
                                         "narrow the inputs' values or sweep fewer inputs")
    return routine


@dataclass(frozen=True)
class _ProgramSection:
    program_file: Path
    symbols_file: Path | None
    load: int | None
    cpu: str
    machine: str
    entry: str
    init: str | None
    program: Program
    entry_address: int
    init_address: int | None
    source_map: SourceMap | None
    entry_s: int

    def fields(self) -> dict:
        return dict(self.__dict__)


def _program_section(r: Fields, doc: dict) -> _ProgramSection:
    """[program]: the file read once, its CPU and machine, entry and init resolved to addresses inside it."""
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
        field_name = "program.symbols" if symbols_file and str(exc).startswith(str(symbols_file)) else "program.file"
        raise r.error(field_name, str(exc)) from None
    if cpu is not None and program.cpu is not None and cpu != program.cpu:
        raise r.error("program.cpu", f"{program_file.name} is a program for the {program.cpu.upper()}, "
                                     f"not the {cpu.upper()}")
    cpu = cpu or program.cpu or "6510"
    machine = _machine(r, program_doc, cpu)
    entry = _entry_text(r, program_doc, "entry", required=True)
    init = _entry_text(r, program_doc, "init")
    entry_address = _in_program(r, program, resolve(r, program, entry, "program.entry"), "program.entry")
    init_address = (_in_program(r, program, resolve(r, program, init, "program.init"), "program.init")
                    if init is not None else None)
    listing_name = _text(r, program_doc, "listing", "program.listing")
    source_map = None
    if listing_name:  # the assembler's listing (ACME --report): coverage by source line
        listing_file = r.file(listing_name, "program.listing", resolve=True)
        try:
            source_map = read_source_map(listing_file)
        except InputError as exc:
            raise r.error("program.listing", str(exc)) from None
    entry_s = r.integer(program_doc["s"], "program.s", 0, 0xFF) if "s" in program_doc else ENTRY_S
    return _ProgramSection(program_file, symbols_file, load, cpu, machine, entry, init, program,
                           entry_address, init_address, source_map, entry_s)


def _places_sections(r: Fields, doc: dict, program: Program, seconds: int, world: World = NO_WORLD,
                     entry_s: int = ENTRY_S
                     ) -> tuple[tuple[Port, ...], tuple[Port, ...], tuple[MemoryBlock, ...]]:
    """[inputs], [outputs] and [memory]: where every value lives, none overlapping."""
    inputs = tuple(port_of(r, program, name, value, "inputs", is_input=True)
                   for name, value in r.table(r.required(doc, "inputs", hint="the [inputs] table"), "inputs").items())
    outputs = tuple(world_output(r, world, name, value) if is_world_output(value) else
                    port_of(r, program, name, value, "outputs", is_input=False)
                    for name, value in r.table(r.required(doc, "outputs", hint="the [outputs] table"),
                                               "outputs").items())
    if not outputs:
        raise r.error("outputs", "names no output")
    no_overlap(r, inputs, "inputs")
    memory = tuple(_memory_block(r, program, name, value, seconds)
                   for name, value in r.table(doc.get("memory", {}), "memory").items())
    _no_overlap_memory(r, memory, inputs)
    inputs, outputs = bind_vias(r, program, inputs, outputs, [(m.address, m.address + m.size, m.name)
                                                              for m in memory if m.size], entry_s)
    return inputs, outputs, memory


def _reference_section(r: Fields, doc: dict, inputs: tuple[Port, ...], memory: tuple[MemoryBlock, ...],
                       rows: tuple[Row, ...], seconds: int, world: World = NO_WORLD) -> dict:
    """[reference]: the function, the memory blocks it takes, whether it works on arrays; none in a
    spec of rows only (the rows say what the routine must answer)."""
    if rows and "reference" not in doc:
        if "cases" in doc:
            raise r.error("cases", "without a [reference] no answer is known for generated cases: write them as rows, "
                                   "or add a [reference]")
        return {"reference": None, "reference_name": "", "reference_memory": (), "reference_arrays": False,
                "world": world}
    reference_doc = r.table(r.required(doc, "reference", hint="the [reference] table, or [[rows]]"), "reference",
                            REFERENCE_KEYS)
    reference_name = _text(r, reference_doc, "function", "reference.function", required=True)
    reference = load_function(reference_name, r, "reference.function", seconds, faults_only=True)
    return {"reference": reference, "reference_name": reference_name,
            "reference_memory": _reference_signature(r, reference, reference_name, inputs, memory, world),
            "world": recorded_mocks(world, *_parameter_names(reference)),
            # true: the function takes numpy arrays, one element per case
            "reference_arrays": r.flag(reference_doc.get("arrays", False), "reference.arrays")}


def _cases_section(r: Fields, doc: dict, inputs: tuple[Port, ...], seconds: int, answered: bool) -> dict:
    """[cases]: exhaustive inputs, random count and seed, the `where` domain, generators. `answered`:
    the spec has a reference (rows only: no generated cases unless asked for)."""
    cases_doc = r.table(doc.get("cases", {}), "cases", CASES_KEYS)
    exhaustive, exhaustive_values = _exhaustive(r, cases_doc.get("exhaustive", []), inputs)
    where = cases_doc.get("where")
    domain = _domain(r, where, inputs) if where is not None else ()
    generators = _generators(r, cases_doc, seconds)
    if cases_doc.get("random_inside") is True and where is None:
        raise r.error("cases.random_inside", "there is no domain (where) to draw inside")
    return {"exhaustive": exhaustive,
            "random": r.integer(cases_doc.get("random", DEFAULT_RANDOM if answered else 0), "cases.random", 0,
                                MAX_RANDOM),
            "seed": r.integer(cases_doc.get("seed", 0), "cases.seed", 0, 2 ** 63 - 1),
            "search": r.integer(cases_doc["search"], "cases.search", 0, MAX_SEARCH) if "search" in cases_doc else None,
            "coverage": _text(r, cases_doc, "coverage", "cases.coverage") or "",
            "domain": domain,
            "exhaustive_values": exhaustive_values,
            "random_values": _part_values(r, r.table(cases_doc.get("random_values", {}), "cases.random_values"),
                                          inputs, "cases.random_values"),
            "random_inside": (r.flag(cases_doc["random_inside"], "cases.random_inside")
                              if "random_inside" in cases_doc else None),
            "boundary": generators.get("boundary"), "sweep": generators.get("sweep"),
            "random_generator": generators.get("random_generator")}


def _exhaustive(r: Fields, exhaustive, inputs: tuple[Port, ...]) -> tuple[tuple[str, ...], tuple]:
    """`cases.exhaustive`: the inputs whose every combination is a case (a list of names), and with a
    table ({ name = values }) the exhaustive part's own values of each."""
    names = tuple(p.name for p in inputs)
    exhaustive_values = ()
    if isinstance(exhaustive, dict):
        exhaustive_values = _part_values(r, exhaustive, inputs, "cases.exhaustive")
        exhaustive = list(exhaustive)
    if not isinstance(exhaustive, list) or not all(isinstance(n, str) for n in exhaustive):
        raise r.error("cases.exhaustive", "expected a list of input names, or a table of input names and their "
                                          "values ({ a = \"0..7\" })")
    unknown = next((n for n in exhaustive if n not in names), None)
    if unknown is not None:
        raise r.error("cases.exhaustive", f"unknown input {unknown!r} (inputs: {', '.join(names)})")
    if len(set(exhaustive)) != len(exhaustive):
        raise r.error("cases.exhaustive", "an input is named twice")
    return tuple(exhaustive), exhaustive_values


def _domain(r: Fields, where, inputs: tuple[Port, ...]) -> tuple:
    """`cases.where` checked against the inputs (tables by element, numbers within what int64 columns hold)."""
    names = tuple(p.name for p in inputs)
    tables = frozenset(p.name for p in inputs if p.table)
    bounds = {p.name: (p.values.lo, p.values.hi) for p in inputs if not p.table}  # what int64 columns must hold
    return parse_where(where, names, f"{r.source}: cases.where", tables, bounds)


def _generators(r: Fields, cases_doc: dict, seconds: int) -> dict:
    """The users' case generators (`boundary`, `sweep`, `random_generator`) loaded under guard; a
    random_generator draws the random cases itself (no random_inside or random_values beside it)."""
    generators = {key: load_function(_text(r, cases_doc, key, f"cases.{key}"), r, f"cases.{key}", seconds)
                  for key in ("boundary", "sweep", "random_generator") if key in cases_doc}
    for key in ("random_inside", "random_values"):
        if key in cases_doc and "random_generator" in generators:
            raise r.error(f"cases.{key}", "the random_generator draws the random cases itself")
    return generators


def _part_values(r: Fields, doc: dict, inputs: tuple[Port, ...], key: str) -> tuple[tuple[str, Values], ...]:
    """{ input = values } of one part of the cases: each a range or a list that fits the input's place
    (it may reach past the input's own `values`: the part's cases take these instead)."""
    ports = {port.name: port for port in inputs}
    out = []
    for name, value in doc.items():
        field_name = f"{key}.{name}"
        if name not in ports:
            raise r.error(field_name, f"unknown input (inputs: {', '.join(ports)})")
        values = parse_values(r, value, field_name)
        check_fits(r, ports[name], values, field_name)
        out.append((name, values))
    return tuple(out)


def _cycles_section(r: Fields, doc: dict, program: Program) -> dict:
    """[cycles]: budget, runaway limit, loop bounds (labels resolved to addresses), static on/off."""
    cycles_doc = r.table(doc.get("cycles", {}), "cycles", CYCLES_KEYS)
    loops_doc = r.table(cycles_doc.get("loops", {}), "cycles.loops")  # label = bound, e.g. { loop = 8 }
    loop_bounds, loop_addresses = {}, {}
    for label, bound in loops_doc.items():
        address = resolve(r, program, label, f"cycles.loops.{label}")
        loop_bounds[label] = r.integer(bound, f"cycles.loops.{label}", 1, MAX_LOOP_BOUND)
        loop_addresses[address] = loop_bounds[label]
    return {"budget": r.integer(cycles_doc["max"], "cycles.max", 1, 1 << 40) if "max" in cycles_doc else None,
            "limit": r.integer(cycles_doc["limit"], "cycles.limit", 1, 1 << 40) if "limit" in cycles_doc else None,
            "loop_bounds": loop_bounds, "loop_addresses": loop_addresses,
            "static": r.flag(cycles_doc.get("static", True), "cycles.static")}


def _summary(r: Fields, doc: dict) -> str:
    summary = doc.get("summary", "")
    if not isinstance(summary, str):
        raise r.error("summary", f"expected a string, got {describe(summary)}")
    return summary


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


def _in_program(r: Fields, program: Program, address: int, field_name: str) -> int:
    """A routine starts in the program's bytes: elsewhere the 6502 would run zeroed RAM."""
    if not program.origin <= address < program.end:
        raise r.error(field_name, f"${address:04X} is outside the program (${program.origin:04X}-${program.end - 1:04X})")
    return address


def _memory_block(r: Fields, program: Program, name: str, doc, seconds: int = sandbox.DEFAULT_SECONDS) -> MemoryBlock:
    key = f"memory.{name}"
    if not name.isidentifier():
        raise r.error(key, "a name must be a Python identifier (the reference may take it by name)")
    if not isinstance(doc, dict):
        raise r.error(key, "expected a table { at = ..., bytes = [...] | file = ... | generator = ... | values + size }")
    r.known(doc, key, MEMORY_KEYS)
    r.required(doc, "at", key)
    (place,) = places_of(r, program, doc["at"], None, f"{key}.at")[:1] or (None,)
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


def _parameter_names(function: Callable) -> tuple[set[str], bool]:
    """The names a function takes, and whether it takes any (**kwargs)."""
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return set(), False
    return set(parameters), any(p.kind == inspect.Parameter.VAR_KEYWORD for p in parameters.values())


def _reference_signature(r: Fields, function: Callable, text: str, inputs: tuple[Port, ...],
                         memory: tuple[MemoryBlock, ...], world: World = NO_WORLD) -> tuple[str, ...]:
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
    known = {port.name for port in inputs} | {m.name for m in memory} | {m.name for m in world.mocks}
    for name in required:
        if name not in known:
            raise r.error("reference.function", f"{text} needs argument {name!r}, which is neither in [inputs] nor "
                                               "a [memory] block nor a mock")
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
