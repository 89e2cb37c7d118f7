"""Entry state as part of a routine's contract: what the caller guarantees, and what is arbitrary.

A spec's `[entry]` table names the registers and flags the caller guarantees on entry
(`[entry] c = 0, d = 0`: carry and decimal clear). Every other register and flag the inputs do not
set is arbitrary, and so is memory that neither the program, an input, a `[memory]` block nor `init`
wrote: the check runs (a sample of) its cases again with that state all ones and random (`VARIANTS`),
and a case whose outputs or cycles change depends on something the spec does not state.

The random values are a pure function of (seed, the case's index in the check): both engines, any
block size and any number of workers give every case the same entry state.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.fields import Fields
from retro.routines.places import FLAGS, REGISTERS, Port

VARIANTS = ("ones", "random")
ENTRY_RNG_OFFSET = 3  # random entry state draws from seed + 3 (cases: seed, memory: seed + 1, exhaustive: seed + 2)
FLAG_ORDER = ("C", "Z", "I", "D", "V", "N")
# how a routine itself sets a flag to the value it needs (6502 instructions)
_FLAG_SETTERS = {("C", 0): "CLC", ("C", 1): "SEC", ("D", 0): "CLD", ("D", 1): "SED", ("I", 0): "CLI",
                 ("I", 1): "SEI", ("V", 0): "CLV", ("V", 1): "BIT a byte with bit 6 set",
                 ("Z", 0): "a load of a non-zero value", ("Z", 1): "a load of 0",
                 ("N", 0): "a load of a value below $80", ("N", 1): "a load of a value from $80"}


def parse_entry(r: Fields, doc, inputs: tuple[Port, ...]) -> tuple[tuple[str, int], ...]:
    """`[entry]`: (place, value) pairs the caller guarantees, places upper case ("A", "C")."""
    doc = r.table(doc, "entry")
    taken = {place.describe(): port.name for port in inputs for place in port.places
             if place.kind in ("register", "flag")}
    state = []
    for key, value in doc.items():
        field = f"entry.{key}"
        place = str(key).upper()
        if place not in REGISTERS and place not in FLAGS:
            raise r.error(field, "unknown register or flag (registers a, x, y; flags c, z, i, d, v, n; memory the "
                                 "caller sets is a [memory] block)")
        if place in taken:
            raise r.error(field, f"{place} is input {taken[place]}: every case sets it")
        if any(p == place for p, _ in state):
            raise r.error(field, f"{place} is named twice")
        state.append((place, r.integer(value, field, 0, 0xFF if place in REGISTERS else 1)))
    return tuple(state)


@dataclass(frozen=True)
class EntryState:
    """What is fixed and what is free on entry to a routine: the registers and P bits no input sets,
    the stated ones at their values, the others free (varied by the entry-state runs)."""

    registers: dict  # register name ("a") -> its value on entry in the baseline run
    flags: int  # P bits set in the baseline run (stated flags, and I unless stated)
    free_registers: tuple[str, ...]  # "a", "x", "y" not set by an input nor stated
    free_flags: tuple[str, ...]  # "C", ... not set by an input nor stated

    @classmethod
    def of(cls, stated: tuple[tuple[str, int], ...], inputs: tuple[Port, ...], vary_interrupt: bool = True) -> "EntryState":
        taken = {place.describe() for port in inputs for place in port.places if place.kind in ("register", "flag")}
        given = dict(stated)
        registers = {name.lower(): given.get(name, 0) for name in REGISTERS}
        flags = FLAGS["I"] if given.get("I", 1) else 0
        for name in FLAG_ORDER:
            if name != "I" and given.get(name):
                flags |= FLAGS[name]
        free_registers = tuple(n.lower() for n in REGISTERS if n not in taken and n not in given)
        # with chips on the bus an interrupt could reach a routine whose I is clear: I stays set there
        free_flags = tuple(n for n in FLAG_ORDER if n not in taken and n not in given and (vary_interrupt or n != "I"))
        return cls(registers, flags, free_registers, free_flags)

    @property
    def free_mask(self) -> int:
        mask = 0
        for name in self.free_flags:
            mask |= FLAGS[name]
        return mask

    def baseline_of(self, place: str) -> int:
        """The value a free register or flag has in the baseline run (what the routine may need)."""
        if place.lower() in self.registers:
            return self.registers[place.lower()]
        return int(bool(self.flags & FLAGS[place]))


def variant_values(state: EntryState, variant: str, seed: int, indices: np.ndarray) -> tuple[dict, np.ndarray]:
    """The free registers (name -> array of bytes) and the free P bits (an array, within the free mask)
    of the cases at `indices` (their places in the check) in one variant."""
    n = len(indices)
    if variant == "ones":
        registers = {name: np.full(n, 0xFF, dtype=np.int64) for name in state.free_registers}
        return registers, np.full(n, state.free_mask, dtype=np.int64)
    key = _mix(np.asarray([(seed + ENTRY_RNG_OFFSET) % 2 ** 64], dtype=np.uint64))[0]
    words = _mix(np.asarray(indices, dtype=np.uint64) ^ key)
    registers = {}
    for k, name in enumerate(("a", "x", "y")):
        if name in state.free_registers:
            registers[name] = ((words >> np.uint64(8 * k)) & np.uint64(0xFF)).astype(np.int64)
    bits = ((words >> np.uint64(32)) & np.uint64(0xFF)).astype(np.int64)
    return registers, bits & state.free_mask


def variant_memory(variant: str, seed: int) -> np.ndarray:
    """The byte every untouched address holds in a variant (65,536 of them)."""
    if variant == "ones":
        return np.full(0x10000, 0xFF, dtype=np.uint8)
    return np.random.default_rng(seed + ENTRY_RNG_OFFSET).integers(0, 256, size=0x10000, dtype=np.uint8)


STACK_TOPS = (0x80, 0xFE)  # the random variant's S before the call's JSR: room for the routine's own stack


def variant_stack(variant: str, seed: int) -> int:
    """S before the call's JSR in a variant (the baseline's is $FF, which "all ones" keeps): one value
    per check, as a caller's stack depth is."""
    if variant == "ones":
        return 0xFF
    word = int(_mix(np.asarray([(seed + ENTRY_RNG_OFFSET) % 2 ** 64], dtype=np.uint64) ^ np.uint64(0x5EED))[0])
    return STACK_TOPS[0] + word % (STACK_TOPS[1] - STACK_TOPS[0] + 1)


def stack_advice(baseline: int, varied: int) -> str:
    return (f"depends on the stack pointer (S = ${baseline - 2:02X} at its first instruction in the check, "
            f"${varied - 2:02X} in a caller with more on the stack): address the stack relative to S (TSX), "
            "never at fixed addresses in page 1")


def _mix(x: np.ndarray) -> np.ndarray:
    """splitmix64's finaliser: a counter -> 64 well-mixed bits (numpy's uint64 arithmetic wraps)."""
    with np.errstate(over="ignore"):
        x = x + np.uint64(0x9E3779B97F4A7C15)
        x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        return x ^ (x >> np.uint64(31))


def advice(place: str, value: int) -> str:
    """What a routine that needs `place` = `value` on entry should do (a register or a flag)."""
    if place in REGISTERS:
        return (f"needs {place} = {value} on entry: add it to the spec ([entry] {place.lower()} = {value}), "
                f"or set it (LD{place} #{value})")
    verb = "clear" if value == 0 else "set"
    return (f"needs {place} = {value} on entry: add it to the spec ([entry] {place.lower()} = {value}), "
            f"or {verb} it ({_FLAG_SETTERS[(place, value)]})")


def memory_advice(address: int, value: int, label: str | None) -> str:
    where = f"${address:04X}" + (f" ({label})" if label else "")
    return (f"reads {where}, which nothing sets before the call (baseline ${value:02X}): declare it (an input, or a "
            f"[memory] block), or write it before reading it")
