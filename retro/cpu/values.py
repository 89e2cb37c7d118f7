"""What the static analysis knows about the 6502's registers, flags and memory at a point of a routine:
an abstract interpretation over sets of byte values (retro.cpu.value_steps gives each instruction's
effect on them, retro.cpu.flow drives it along the paths).

A byte is a set of the values it may hold, kept as a 256-bit integer (bit v set: v is possible), so
a join is an OR and INX a rotation. A flag is a 2-bit set (bit 0: may be clear, bit 1: may be set).
Memory is the routine's view of it: bytes it stored on the way (`State.stored`), else what
`MemoryModel.initial` says (the program and tables as loaded, the inputs' `values`, anything else
unknown). Results that would need too many combinations of operands are taken as unknown: the sets
only ever grow toward "any value", so every answer holds for every run that starts inside the
entry state (the analysis over-approximates, it never guesses).

Assumptions, stated where the static analysis is documented (docs/specs.md): a store whose address
is unknown (a pointer or index with too many values) writes neither the program's own bytes nor
the stack; the stack page is never read as data; decimal-mode ADC/SBC on the NMOS CPUs give an
unknown result (their timing does not change).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

ANY = (1 << 256) - 1  # a byte that may hold any value
NONE = 0
LOW_HALF = (1 << 128) - 1  # values 0..127 (bit 7 clear)
HIGH_HALF = ANY ^ LOW_HALF
CLEAR, SET, EITHER = 1, 2, 3  # a flag's possible values
STACK_PAGE = 0x0100


def single(value: int) -> int:
    return 1 << (value & 0xFF)


def span(lo: int, hi: int) -> int:
    """The set lo..hi (bytes)."""
    return ((1 << (hi + 1)) - 1) ^ ((1 << lo) - 1)


def members(mask: int) -> Iterator[int]:
    while mask:
        low = mask & -mask
        yield low.bit_length() - 1
        mask ^= low


def lowest(mask: int) -> int:
    return (mask & -mask).bit_length() - 1


def highest(mask: int) -> int:
    return mask.bit_length() - 1


def is_single(mask: int) -> bool:
    return mask != 0 and mask & (mask - 1) == 0


def of_values(values) -> int:
    mask = 0
    for v in values:
        mask |= 1 << (v & 0xFF)
    return mask


def flag_of(bits: set[bool] | tuple[bool, ...]) -> int:
    return (SET if True in bits else 0) | (CLEAR if False in bits else 0)


def zero_flag(mask: int) -> int:
    return (SET if mask & 1 else 0) | (CLEAR if mask & ~1 else 0)


def negative_flag(mask: int) -> int:
    return (SET if mask & HIGH_HALF else 0) | (CLEAR if mask & LOW_HALF else 0)


def increment(mask: int) -> int:
    return ((mask << 1) & ANY) | (mask >> 255)


def decrement(mask: int) -> int:
    return (mask >> 1) | ((mask & 1) << 255)


def mapped(mask: int, function: Callable[[int], int]) -> int:
    if mask == ANY:
        return of_values(function(v) for v in range(256))
    return of_values(function(v) for v in members(mask))


def flag_values(flag: int) -> tuple[int, ...]:
    return tuple(v for v, bit in ((0, CLEAR), (1, SET)) if flag & bit)


@dataclass(frozen=True)
class MemoryModel:
    """Memory when the routine is entered: `initial(address)` -> the set of values a byte may hold;
    `program` (start, end): bytes a store through an unknown address is assumed not to reach."""

    initial: Callable[[int], int]
    program: tuple[int, int] = (0, 0)

    def protected(self, address: int) -> bool:
        return self.program[0] <= address < self.program[1]


@dataclass(frozen=True)
class State:
    """The registers, flags, stack and stored bytes at one point; immutable (each step makes a new one)."""

    a: int = ANY
    x: int = ANY
    y: int = ANY
    c: int = EITHER
    z: int = EITHER
    n: int = EITHER
    v: int = EITHER
    d: int = EITHER
    stored: tuple[tuple[int, int], ...] = ()  # (address, set) the routine wrote, sorted by address
    wild: bool = False  # a store went to an unknown address: unprotected memory is unknown
    stack: tuple | None = ()  # pushed items (("a", set) or ("p", flags)); None: unknown (after TXS)
    nz: str = ""  # the register ("a", "x", "y") whose value N and Z were last set from ("": none)
    _index: dict = field(default=None, compare=False, hash=False, repr=False)

    def changed(self, **changes) -> State:
        """This state with `changes`: dataclasses.replace without its per-call work (a static analysis
        makes tens of thousands of states: tile_box's 21,750), field names still checked."""
        if not changes.keys() <= _STATE_FIELDS:
            raise TypeError(f"State has no field {sorted(changes.keys() - _STATE_FIELDS)[0]!r}")
        new = object.__new__(State)
        new.__dict__.update(self.__dict__)
        new.__dict__.update(changes)
        return new

    def read(self, memory: MemoryModel, address: int) -> int:
        address &= 0xFFFF
        if address >> 8 == STACK_PAGE >> 8:
            return ANY
        index = self._lookup()
        if address in index:
            return index[address]
        if self.wild and not memory.protected(address):
            return ANY
        return memory.initial(address)

    def _lookup(self) -> dict:
        if self._index is None:
            object.__setattr__(self, "_index", dict(self.stored))
        return self._index

    def written(self, memory: MemoryModel, addresses: set[int] | None, value: int) -> "State":
        """The state after a store of `value` to one of `addresses` (None: an unknown address)."""
        if addresses is None:
            kept = tuple((a, v) for a, v in self.stored if memory.protected(a))
            return self.changed(stored=kept, wild=True, _index=None)
        index = dict(self._lookup())
        strong = len(addresses) == 1
        for address in addresses:
            if address >> 8 == STACK_PAGE >> 8:
                continue
            index[address] = value if strong else value | self.read(memory, address)
        return self.changed(stored=tuple(sorted(index.items())), _index=None)

    def join(self, other: "State", memory: MemoryModel) -> "State":
        if other is self:
            return self
        mine, theirs = self._lookup(), other._lookup()
        stored = []
        for address in sorted(set(mine) | set(theirs)):
            stored.append((address, (mine[address] if address in mine else self.read(memory, address))
                           | (theirs[address] if address in theirs else other.read(memory, address))))
        if self.stack is not None and other.stack is not None and len(self.stack) == len(other.stack):
            stack = tuple(_join_item(p, q) for p, q in zip(self.stack, other.stack))
        else:
            stack = None
        return State(self.a | other.a, self.x | other.x, self.y | other.y, self.c | other.c, self.z | other.z,
                     self.n | other.n, self.v | other.v, self.d | other.d, tuple(stored), self.wild or other.wild,
                     stack, self.nz if self.nz == other.nz else "")

    def pushed(self, item: tuple) -> "State":
        return self.changed(stack=None if self.stack is None else (*self.stack, item))

    def pulled(self) -> tuple[tuple | None, "State"]:
        if not self.stack:
            return None, self.changed(stack=None)
        return self.stack[-1], self.changed(stack=self.stack[:-1])

    def flags(self) -> tuple[int, int, int, int, int]:
        return self.c, self.z, self.n, self.v, self.d


_STATE_FIELDS = frozenset(State.__dataclass_fields__)


def _join_item(p: tuple, q: tuple) -> tuple:
    if p[0] == q[0] == "a":
        return ("a", p[1] | q[1])
    if p[0] == q[0] == "p":
        return ("p", tuple(f | g for f, g in zip(p[1], q[1])))
    return ("a", ANY)


def narrowed(state: State, register: str, mask: int) -> State:
    """The state with a register (a, x, y) or flag (c, z, n, v, d) known to lie in `mask`; N and Z
    and the register they were set from narrow each other (after `LDA / BEQ`, A is 0 where taken)."""
    changes = {register: getattr(state, register) & mask}
    source = state.nz
    if register == source:
        changes["z"] = state.z & zero_flag(changes[register])
        changes["n"] = state.n & negative_flag(changes[register])
    elif register in ("z", "n") and source:
        value = getattr(state, source)
        if register == "z":
            value &= {SET: single(0), CLEAR: ANY ^ single(0)}.get(mask, ANY)
        else:
            value &= {SET: HIGH_HALF, CLEAR: LOW_HALF}.get(mask, ANY)
        changes[source] = value
    return state.changed(**changes)


def is_empty(state: State) -> bool:
    return not (state.a and state.x and state.y and state.c and state.z and state.n and state.v and state.d)
