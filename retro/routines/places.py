"""Where a routine's values live, as a spec writes them: registers, flags, labels (`label+N`) or
addresses, resolved against the program's symbols -> `Place`s; an input's or output's `Port`
(a number over byte places, or a table) and the `Values` an input takes. Every error names the key.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

from retro.cpu.machine import STACK_BASE
from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_V, FLAG_Z
from retro.fields import Fields, describe
from retro.program import Program

BYTE_VALUES = 256
MAX_TABLE = 0x10000
REGISTERS = ("A", "X", "Y")
FLAGS = {"C": FLAG_C, "Z": FLAG_Z, "I": FLAG_I, "D": FLAG_D, "V": FLAG_V, "N": FLAG_N}
PORT_KEYS = {"at", "size", "values", "table"}

# Addressing-mode notation for a value whose place depends on the case (docs/specs.md, "Calling
# conventions"): `3,S` on the stack, `obj_x,X` a slot of a table, `(ptr),Y` / `(ptr)+2` behind a pointer.
_STACK = re.compile(r"^(?P<offset>[^,()]+?)\s*,\s*S$", re.IGNORECASE)
_POINTER = re.compile(r"^\(\s*(?P<pointer>[^(),]+?)\s*\)\s*(?:,\s*(?P<index>Y)|\+\s*(?P<offset>\S+))?$", re.IGNORECASE)
_INDEXED = re.compile(r"^(?P<base>[^,()]+?)\s*,\s*(?P<index>[XY])$", re.IGNORECASE)
FIRST_ARGUMENT = 3  # 1,S and 2,S hold the return address the JSR pushed: the caller's bytes start at 3,S
_LABEL = re.compile(r"^(?P<name>[A-Za-z_@.][\w.:@]*)\s*(?:(?P<sign>[+-])\s*(?P<offset>\S+))?$")


@dataclass(frozen=True)
class Place:
    """Where one byte (or one flag bit) of a value lives."""

    kind: str  # "register" (A/X/Y), "flag" (a P bit) or "memory"
    register: str = ""  # "a", "x", "y" for registers
    bit: int = 0  # the P bit for flags
    address: int = 0  # for memory

    def describe(self) -> str:
        if self.kind == "via":  # byte `address` of a value whose place depends on the case (Port.via)
            return f"+{self.address}"
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
class Via:
    """Where a port's first byte lies when the case decides it, as a 6502 instruction would reach it:
    `stack` ($0100 + S + base, S at entry), `indexed` (a table at base, slot = X or Y at entry;
    a zero-page table wraps in zero page as zp,X does) or `pointer` (the word at base, + offset,
    + Y at entry). Inputs are named by their index in the routine's inputs; -1: none (a fixed S, a
    pointer no input sets: read from memory as it stands after `init`)."""

    mode: str  # "stack", "indexed" or "pointer"
    text: str  # as the spec writes it
    base: int  # stack: the offset from S; indexed: the table's address; pointer: the pointer's address
    index: str = ""  # "x" or "y": the register whose value at entry indexes (indexed; pointer with ,Y)
    offset: int = 0  # pointer: bytes added to the pointer
    pointer_name: str = ""  # pointer: the input or label in the parentheses, as written
    index_input: int = -1  # the input that sets the index register
    pointer_input: int = -1  # the input that sets the pointer (a two-byte number at base)
    s_input: int = -1  # stack: the input that sets S (-1: the spec's fixed S)

    def describe(self) -> str:
        if self.mode == "stack":
            return f"${self.base:02X},S"
        if self.mode == "indexed":
            return f"${self.base:0{2 if self.base < 0x100 else 4}X},{self.index.upper()}"
        pointer = f"(${self.base:0{2 if self.base < 0x100 else 4}X})"
        return pointer + (",Y" if self.index else f"+{self.offset}" if self.offset else "")


@dataclass(frozen=True)
class Port:
    """An input or an output: a number over one or more byte places (low byte first), or a table."""

    name: str
    places: tuple[Place, ...]
    table: bool = False  # a list of bytes at consecutive addresses, not one number
    values: Values | None = None  # inputs only: per value (per byte for a table)
    via: Via | None = None  # its place depends on the case (stack, table slot, pointer): places are offsets
    address: bool = False  # the value is an address (a pointer, S): reports show it in $hex

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
        if self.via is not None:
            return self.via.describe() + (f" ({len(self.places)} bytes)" if len(self.places) > 1 else "")
        if self.table:
            return f"{len(self.places)} bytes at {self.places[0].describe()}"
        return "+".join(p.describe() for p in self.places)


def resolve(r: Fields, program: Program, text: str, field_name: str) -> int:
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
        base = resolve(r, program, match.group("name"), field_name)
        offset = r.integer(match.group("offset"), field_name, 0, 0xFFFF)
        address = base + offset if match.group("sign") == "+" else base - offset
        if not 0 <= address <= 0xFFFF:
            raise r.error(field_name, f"{text} is outside $0000-$FFFF")
        return address
    hint = " (registers are written A, X, Y and flags C, Z, I, D, V, N)" if text.upper() in (*REGISTERS, *FLAGS) else ""
    if not program.symbols:
        hint = f" ({program.source or 'the program'} has no symbols: give [program] symbols, or an address)"
    raise r.error(field_name, f"unknown label {text!r}{hint}")


def places_of(r: Fields, program: Program, at, size: int | None, key: str) -> tuple[Place, ...]:
    """`at` (one item or a list: registers, flags, `S`, labels or addresses) -> its places; with
    `size`, that many bytes from one memory location."""
    items = at if isinstance(at, list) else [at]
    if not items:
        raise r.error(key, "expected a register, flag, label or address")
    places = [_place(r, program, item, key) for item in items]
    if size is not None:
        if len(places) != 1 or places[0].kind != "memory":
            raise r.error(key, "size goes with one memory location (a label or an address)")
        start = places[0].address
        if start + size > 0x10000:
            raise r.error(key, f"{size} bytes from ${start:04X} run past $FFFF")
        places = [Place("memory", address=start + i) for i in range(size)]
    if len(places) > 1:
        if any(p.kind == "flag" for p in places):
            raise r.error(key, "a flag is one bit: it cannot be combined with other places")
        if any(p.register == "s" for p in places):
            raise r.error(key, "S is one byte: it cannot be combined with other places")
    return tuple(places)


def _place(r: Fields, program: Program, item, key: str) -> Place:
    """One item of `at`: `S`, a register, a flag, or a label or address of memory."""
    if isinstance(item, int) and not isinstance(item, bool):
        item = str(item)
    if not isinstance(item, str) or not item.strip():
        raise r.error(key, f"expected a register, flag, label or address, got {item!r:.40}")
    text = item.strip()
    if text == "S":  # the stack pointer at entry (an input only: after the RTS it is S + 2)
        return Place("register", register="s")
    if text in REGISTERS:
        return Place("register", register=text.lower())
    if text in FLAGS:
        return Place("flag", bit=FLAGS[text])
    return Place("memory", address=resolve(r, program, text, key))


def via_of(r: Fields, program: Program, at, key: str) -> Via | None:
    """`at` in addressing-mode notation (`3,S`, `obj_x,X`, `(ptr),Y`, `(ptr)+2`), or None for a fixed
    place. A pointer's name is resolved later (`bind_vias`): it may name another input."""
    if not isinstance(at, str):
        return None
    text = at.strip()
    if match := _STACK.match(text):
        offset = r.integer(match.group("offset").strip(), key, 0, 0xFF)
        if offset < FIRST_ARGUMENT:
            raise r.error(key, f"{text}: 1,S and 2,S hold the return address the JSR pushed; the byte the caller "
                               f"pushed last is at 3,S")
        return Via("stack", text, offset)
    if match := _POINTER.match(text):
        offset = r.integer(match.group("offset"), key, 0, 0xFFFF) if match.group("offset") else 0
        return Via("pointer", text, -1, "y" if match.group("index") else "", offset, match.group("pointer"))
    if match := _INDEXED.match(text):
        return Via("indexed", text, resolve(r, program, match.group("base").strip(), key), match.group("index").lower())
    if "(" in text or text.count(",") == 1:
        raise r.error(key, f"{text!r} is not a place: write 3,S (stack, S at entry), table,X or table,Y (a slot "
                           "picked by an index input), (ptr), (ptr)+N or (ptr),Y (behind a pointer)")
    return None


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


def port_of(r: Fields, program: Program, name: str, value, section: str, is_input: bool) -> Port:
    """An `[inputs]` or `[outputs]` entry (a location, or a table { at, size, values, table }) -> its Port."""
    key = f"{section}.{name}"
    if not name.isidentifier() or name.startswith("__"):
        raise r.error(key, "a name must be a Python identifier (it names the reference's argument)")
    doc = {"at": value} if isinstance(value, (str, list)) else value
    if not isinstance(doc, dict):
        raise r.error(key, "expected a location (\"A\", \"C\", \"label\", \"$fb\") or a table { at = ... }")
    r.known(doc, key, PORT_KEYS if is_input else PORT_KEYS - {"values"})
    r.required(doc, "at", key)
    size = r.integer(doc["size"], f"{key}.size", 1, MAX_TABLE) if "size" in doc else None
    via = via_of(r, program, doc["at"], f"{key}.at")
    if via is not None:  # bytes counted from where the case puts the first (bind_vias)
        places = tuple(Place("via", address=i) for i in range(size or 1))
    else:
        places = places_of(r, program, doc["at"], size, f"{key}.at")
    if not is_input and places[0].register == "s":
        raise r.error(f"{key}.at", "S after the routine's RTS is S at entry + 2: it is not an output")
    values = parse_values(r, doc["values"], f"{key}.values") if "values" in doc else None
    table = _is_table(r, doc, key, size, values, is_input)
    if table and (size is None or places[0].kind not in ("memory", "via")):
        raise r.error(f"{key}.table", "a table needs a memory location and a size")
    return Port(name, places, table, _port_values(r, Port(name, places, table, None), values, key, is_input), via)


def _is_table(r: Fields, doc: dict, key: str, size: int | None, values: Values | None, is_input: bool) -> bool:
    """Whether a port is a table of bytes: as `table` says, else `size` N with byte values is a table
    of N bytes and anything else an N-byte little-endian number; an input's size > 1 with neither
    values nor `table` is ambiguous (an error saying how to choose)."""
    table_flag = r.flag(doc["table"], f"{key}.table") if "table" in doc else None
    if table_flag is not None:
        return table_flag
    wide = size is not None and size > 1
    if is_input and wide and values is None:
        raise r.error(f"{key}.size", f"size = {size} without values is ambiguous: a {8 * size}-bit number, or a table "
                                     f"of {size} bytes? Say which: table = false (a number; or values = \"LO..HI\"), "
                                     f"or values = \"0..255\" (a table, each byte from those values; or table = true)")
    return wide and values is not None and values.hi < BYTE_VALUES


def _port_values(r: Fields, port: Port, values: Values | None, key: str, is_input: bool) -> Values | None:
    """The values an input takes (all that fit when not given), each fitting its places."""
    if values is None and is_input:
        values = Values(0, value_limit(port) - 1)
    if values is not None:
        check_fits(r, port, values, f"{key}.values")
    return values


def value_limit(port: Port) -> int:
    """One more than the largest value that fits the port's places (a table's: each byte's)."""
    return BYTE_VALUES if port.table else 1 << port.bits


def check_fits(r: Fields, port: Port, values: Values, key: str) -> None:
    """Values given for a port (its own, or a part's of the cases) must fit its places."""
    limit = value_limit(port)
    if values.hi >= limit:
        raise r.error(key, f"{values.describe()} does not fit in {port.describe()} "
                           f"({'each byte ' if port.table else ''}0..{limit - 1})")


def no_overlap(r: Fields, ports: tuple[Port, ...], section: str) -> None:
    owner: dict[Place, str] = {}
    for port in ports:
        for place in port.places if port.via is None else ():  # bind_vias checks those
            if place in owner:
                raise r.error(f"{section}.{port.name}.at",
                              f"{place.describe()} is also where {section}.{owner[place]} goes")
            owner[place] = port.name


def bind_vias(r: Fields, program: Program, inputs: tuple[Port, ...], outputs: tuple[Port, ...],
              blocks: list[tuple[int, int, str]], entry_s: int) -> tuple[tuple[Port, ...], tuple[Port, ...]]:
    """The ports placed by the case (`Via`) tied to the inputs that place them (the index register, S,
    the pointer), and the places every input may take checked against each other and against the
    fixed inputs and the `[memory]` blocks ((start, end, name)). Pointers and S are marked as
    addresses (reports print them in $hex)."""
    register_inputs = {p.places[0].register: i for i, p in enumerate(inputs)
                       if len(p.places) == 1 and p.places[0].kind == "register"}
    bound = {section: [_bind(r, program, port, f"{section}.{port.name}.at", inputs, register_inputs)
                       for port in ports] for section, ports in (("inputs", inputs), ("outputs", outputs))}
    pointers = {port.via.pointer_input for port in bound["inputs"] + bound["outputs"] if port.via is not None}
    pointers.add(register_inputs.get("s", -1))
    new_inputs = tuple(replace(port, address=True) if i in pointers else port for i, port in enumerate(bound["inputs"]))
    _no_via_overlap(r, new_inputs, blocks, entry_s)
    return new_inputs, tuple(bound["outputs"])


def _bind(r: Fields, program: Program, port: Port, key: str, inputs: tuple[Port, ...],
          register_inputs: dict[str, int]) -> Port:
    """A port placed by the case tied to the inputs that place it: the index register's, S's, the pointer's."""
    via = port.via
    if via is None:
        return port
    if via.index:
        if via.index not in register_inputs:
            name = via.index.upper()
            raise r.error(key, f"{via.text}: {name} is not an input: name it in [inputs] (e.g. slot = {{ at = \"{name}\", "
                               f"values = \"0..7\" }}); its values are the slots checked")
        via = replace(via, index_input=register_inputs[via.index])
    if via.mode == "stack":
        return replace(port, via=replace(via, s_input=register_inputs.get("s", -1)))
    if via.mode != "pointer":
        return replace(port, via=via)
    base = _pointer_address(r, program, via, key, inputs)
    return replace(port, via=replace(via, base=base, pointer_input=_pointer_input(r, via, key, inputs, base)))


def _pointer_address(r: Fields, program: Program, via: Via, key: str, inputs: tuple[Port, ...]) -> int:
    """Where the pointer in `(ptr)` lies: the input it names (a two-byte number in memory), or a label or address."""
    holder = next((p for p in inputs if p.name == via.pointer_name), None)
    if holder is None:
        return resolve(r, program, via.pointer_name, key)
    if holder.via is not None or holder.table or holder.places[0].kind != "memory" or len(holder.places) != 2:
        raise r.error(key, f"{via.text}: inputs.{holder.name} is not a pointer (a two-byte number at a label or "
                           f"address: {{ at = \"$fb\", size = 2, values = \"...\" }})")
    return holder.places[0].address


def _pointer_input(r: Fields, via: Via, key: str, inputs: tuple[Port, ...], base: int) -> int:
    """The input that sets the pointer's two bytes at `base` (-1: none); one that holds only a part of them is an error."""
    pointer_bytes = (base, (base + 1) & 0xFF if base < 0x100 else (base + 1) & 0xFFFF)  # ($FF) wraps as the 6502 does
    pointer_input = -1
    for i, holder in enumerate(inputs):
        held = {p.address for p in holder.places if p.kind == "memory"} if holder.via is None else set()
        if not held & set(pointer_bytes):
            continue
        if holder.table or tuple(p.address for p in holder.places) != pointer_bytes:
            raise r.error(key, f"{via.text}: the pointer's bytes ${pointer_bytes[0]:04X}/${pointer_bytes[1]:04X} are "
                               f"split over inputs.{holder.name}: make the pointer one input of size 2 at ${base:04X}")
        pointer_input = i
    return pointer_input


def via_span(via: Via, size: int, inputs: tuple[Port, ...], entry_s: int):
    """Every address the port's bytes may take over the case's values (a set, or a range for a
    pointer input), or None when it is only known at run time (a pointer no input sets)."""
    def listed(port: Port) -> list[int]:
        values = port.values
        return list(values.listed) if values.listed is not None else list(range(values.lo, values.hi + 1))
    indexes = listed(inputs[via.index_input]) if via.index_input >= 0 else [0]
    if via.mode == "stack":
        esses = listed(inputs[via.s_input]) if via.s_input >= 0 else [entry_s]
        return {STACK_BASE | ((s + via.base + i) & 0xFF) for s in esses for i in range(size)}
    if via.mode == "indexed":
        wrap = 0xFF if via.base < 0x100 else 0xFFFF
        return {(via.base + j + i) & wrap for j in indexes for i in range(size)}
    if via.pointer_input < 0:
        return None
    pointer = inputs[via.pointer_input].values
    return range(pointer.lo + via.offset + min(indexes), pointer.hi + via.offset + max(indexes) + size)


def _no_via_overlap(r: Fields, inputs: tuple[Port, ...], blocks: list[tuple[int, int, str]], entry_s: int) -> None:
    """An input placed by the case may not reach another input's place, nor a `[memory]` block; two
    at one anchor (the same pointer and index, or the stack) only may not share an offset."""
    fixed = {p.address: port.name for port in inputs if port.via is None for p in port.places if p.kind == "memory"}
    spans = []
    for port in inputs:
        if port.via is None:
            continue
        key = f"inputs.{port.name}.at"
        span = via_span(port.via, len(port.places), inputs, entry_s)
        if span is None:
            continue
        if span.stop > 0x10000 if isinstance(span, range) else False:
            raise r.error(key, f"{port.via.text}: the pointer's values reach past $FFFF (up to ${span.stop - 1:X}): "
                               "narrow the pointer's values")
        for address, name in fixed.items():
            if address in span:
                raise r.error(key, f"{port.via.text} may reach ${address:04X}, where inputs.{name} goes")
        for start, end, name in blocks:
            if _meets(span, range(start, end)):
                raise r.error(key, f"{port.via.text} may reach into memory.{name} (${start:04X}-${end - 1:04X}): an "
                                   "input is set for every case")
        for other, other_span in spans:
            if port.via.mode != "indexed" and _anchor(port.via) == _anchor(other.via):
                if _meets(_offsets(port), _offsets(other)):  # the same place in some case
                    raise r.error(key, f"{port.via.text} shares bytes with inputs.{other.name} ({other.via.text})")
            elif _meets(span, other_span):
                raise r.error(key, f"{port.via.text} may reach the bytes of inputs.{other.name} ({other.via.text})")
        spans.append((port, span))


def _anchor(via: Via) -> tuple:
    """What places a port's bytes, apart from its own offset: ports at one anchor move together."""
    return via.mode, via.base if via.mode == "pointer" else None, via.index_input, via.s_input, via.pointer_input


def _offsets(port: Port) -> range:
    start = port.via.base if port.via.mode == "stack" else port.via.offset
    return range(start, start + len(port.places))


def _meets(a, b) -> bool:
    if a is None or b is None:
        return False
    if isinstance(a, range) and isinstance(b, range):
        return max(a.start, b.start) < min(a.stop, b.stop)
    small, large = (a, b) if not isinstance(a, range) else (b, a)
    return any(x in large for x in small)
