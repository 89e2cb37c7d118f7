"""Where a routine's values live, as a spec writes them: registers, flags, labels (`label+N`) or
addresses, resolved against the program's symbols -> `Place`s; an input's or output's `Port`
(a number over byte places, or a table) and the `Values` an input takes. Every error names the key.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_V, FLAG_Z
from retro.fields import Fields, describe
from retro.program import Program

BYTE_VALUES = 256
MAX_TABLE = 0x10000
REGISTERS = ("A", "X", "Y")
FLAGS = {"C": FLAG_C, "Z": FLAG_Z, "I": FLAG_I, "D": FLAG_D, "V": FLAG_V, "N": FLAG_N}
PORT_KEYS = {"at", "size", "values", "table"}

_LABEL = re.compile(r"^(?P<name>[A-Za-z_@.][\w.:@]*)\s*(?:(?P<sign>[+-])\s*(?P<offset>\S+))?$")


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
            places.append(Place("memory", address=resolve(r, program, text, key)))
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


def port_of(r: Fields, program: Program, name: str, value, section: str, is_input: bool) -> Port:
    key = f"{section}.{name}"
    if not name.isidentifier() or name.startswith("__"):
        raise r.error(key, "a name must be a Python identifier (it names the reference's argument)")
    doc = {"at": value} if isinstance(value, (str, list)) else value
    if not isinstance(doc, dict):
        raise r.error(key, "expected a location (\"A\", \"C\", \"label\", \"$fb\") or a table { at = ... }")
    r.known(doc, key, PORT_KEYS if is_input else PORT_KEYS - {"values"})
    r.required(doc, "at", key)
    size = r.integer(doc["size"], f"{key}.size", 1, MAX_TABLE) if "size" in doc else None
    places = places_of(r, program, doc["at"], size, f"{key}.at")
    values = parse_values(r, doc["values"], f"{key}.values") if "values" in doc else None
    table_flag = r.flag(doc["table"], f"{key}.table") if "table" in doc else None
    # `size` N with byte values is a table of N bytes; otherwise an N-byte little-endian number
    table = table_flag if table_flag is not None else (
        size is not None and size > 1 and values is not None and values.hi < BYTE_VALUES)
    if table and (size is None or places[0].kind != "memory"):
        raise r.error(f"{key}.table", "a table needs a memory location and a size")
    return Port(name, places, table, _port_values(r, Port(name, places, table, None), values, key, is_input))


def _port_values(r: Fields, port: Port, values: Values | None, key: str, is_input: bool) -> Values | None:
    """The values an input takes (all that fit when not given), each fitting its places."""
    limit = BYTE_VALUES if port.table else 1 << port.bits
    if values is None and is_input:
        values = Values(0, limit - 1)
    if values is not None and values.hi >= limit:
        raise r.error(f"{key}.values", f"{values.describe()} does not fit in {port.describe()} "
                                      f"({'each byte ' if port.table else ''}0..{limit - 1})")
    return values


def no_overlap(r: Fields, ports: tuple[Port, ...], section: str) -> None:
    owner: dict[Place, str] = {}
    for port in ports:
        for place in port.places:
            if place in owner:
                raise r.error(f"{section}.{port.name}.at",
                              f"{place.describe()} is also where {section}.{owner[place]} goes")
            owner[place] = port.name
