"""Which of a routine's forward branches the compiled engine runs without branching (if-conversion):
pure analysis of the code's shape for `retro.cpu.translate`, which emits them.

A conditional branch whose two ways are short straight-line code that meet again (a triangle: a branch
over a few instructions; a diamond: two short ways to a common address; or two ways that each end at
an RTS) is a `Region`: the generated code runs both ways one after the other and keeps the state of the
one the branch takes by selection (`x = x if c else other`, which LLVM compiles without a jump). A call
on random data then pays no mispredicted jump there (aabb8's compare chains, tile's table tests): the
host CPU guesses a data-dependent 6502 branch wrong half the time, and each wrong guess costs about as
much as a dozen translated instructions.

What a way may hold is the translator's to say (`Classify`): instructions without control flow or
stack effects, stores only to fixed addresses (the translator makes them conditional on the way being
the one taken), forward JMP and BRA, and branches that are regions themselves (nested: a tree of
branches whose ways all end at an RTS converts whole). Every address a way passes through is higher
than the one before, so the analysis ends and converts no loop. A region's cost (the instructions the
converted code runs on every call, both ways and all nested ways) is held under MAX_COST: above it,
running everything costs more than the jumps it saves.

Two ways that do not meet but each end at a branch of their own to the same two addresses (tile's
table tests) convert as a merged exit: both branches are evaluated, the way taken's decides, and the
choice between the two addresses is a region of its own (`Region.then`), so the shared tails run once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from retro.cpu.opcodes import MODE_LENGTH, Op
from retro.cpu.timing import branch_target

WORD = 0xFFFF
RTS_JOIN = -1  # a region whose ways all end at an RTS: the converted code then runs one RTS
MAX_COST = 10  # instructions a region's converted code may run per call (both ways, nested ones included)

# The translator's classification of an instruction inside a way: None where a way must stop before it,
# else (cost, whether it stores to memory).
Classify = Callable[[int, Op], "tuple[int, bool] | None"]


@dataclass(frozen=True)
class Way:
    """One way from a branch: `items` in order, each (pc, Region or None: the instruction at pc, its cost,
    whether it stores), up to `end` (the address where the way meets the other, or RTS_JOIN)."""

    items: tuple[tuple[int, "Region | None", int, bool], ...]
    end: int

    @property
    def cost(self) -> int:
        return sum(cost for _, _, cost, _ in self.items)

    @property
    def stores(self) -> bool:
        return any(stores for _, _, _, stores in self.items)

    def boundaries(self) -> list[int]:
        """The addresses the way passes through between its items (its end included)."""
        return [item[0] for item in self.items] + ([self.end] if self.end != RTS_JOIN else [])

    def until(self, address: int) -> "Way":
        """The way cut where it reaches `address` (one of its boundaries)."""
        items = []
        for item in self.items:
            if item[0] == address:
                break
            items.append(item)
        return Way(tuple(items), address)


@dataclass(frozen=True)
class Region:
    """A converted branch at `pc`: its taken and its not-taken way to `join`. Or, when `exits` names
    them, ways that each end at a branch of their own (taken way's first) to the same two addresses:
    both of those branches are evaluated, the one on the way taken decides, and `then` is the
    converted choice between the two addresses (its pc: the taken way's branch; its taken way: from
    that branch's target), which ends at `join` (tile: BCS to two table tests that both go to the
    same two tails)."""

    pc: int
    taken: Way
    fall: Way
    join: int  # the address both ways reach, or RTS_JOIN: both end at an RTS (not run inside the ways)
    exits: tuple[int, ...] = ()
    then: "Region | None" = None

    @property
    def cost(self) -> int:
        return 1 + self.taken.cost + self.fall.cost + len(self.exits) + (self.then.cost if self.then else 0)

    @property
    def stores(self) -> bool:
        return self.taken.stores or self.fall.stores or (self.then is not None and self.then.stores)


def plan(instructions: dict[int, Op | None], leaders: set[int], read: Callable[[int], int], return_pc: int,
         classify: Classify) -> dict[int, Region]:
    """Every conditional branch of the code that converts: {pc of the branch: Region}."""
    found: dict[int, Region | None] = {}

    def walk(pc: int, nested: bool = True) -> Way:
        """The way from pc (`nested`: through the branches that convert, else to the first branch)."""
        items: list = []
        spent = 0
        passed = set()
        while pc != return_pc and spent <= MAX_COST and pc not in passed:  # a way never runs a loop
            passed.add(pc)
            op = instructions.get(pc)
            if op is None:
                break
            if op.mnemonic == "RTS":
                return Way(tuple(items), RTS_JOIN)
            following = pc + MODE_LENGTH[op.mode]
            if op.mode in ("rel", "zpr") and op.mnemonic != "BRA":
                region = region_at(pc) if nested else None
                if region is None:
                    break
                items.append((pc, region, region.cost, region.stores))
                spent += region.cost
                if region.join == RTS_JOIN:
                    return Way(tuple(items), RTS_JOIN)
                pc = region.join
                continue
            if op.mnemonic == "BRA" or (op.mnemonic == "JMP" and op.mode == "abs"):
                target = (branch_target(pc, read((pc + 1) & WORD)) if op.mnemonic == "BRA"
                          else read((pc + 1) & WORD) | read((pc + 2) & WORD) << 8)
                items.append((pc, None, 1, False))
                spent += 1
                pc = target
                continue
            kind = classify(pc, op)
            if kind is None or following > WORD:
                break
            items.append((pc, None, *kind))
            spent += kind[0]
            pc = following
        return Way(tuple(items), pc)

    def meeting(pc: int, taken: Way, fall: Way) -> Region | None:
        """The region of two ways that meet (at an address, or each at an RTS), else None."""
        common = [address for address in fall.boundaries() if address in set(taken.boundaries())]
        if common and (common[0] in leaders or common[0] == return_pc):
            join = common[0]  # the first address the way not taken reaches that the taken one reaches too
            return Region(pc, taken.until(join), fall.until(join), join)
        if taken.end == RTS_JOIN and fall.end == RTS_JOIN:
            return Region(pc, taken, fall, RTS_JOIN)
        return None

    def targets(pc: int) -> tuple[int, int] | None:
        """(target, following) of the conditional branch at pc, else None."""
        op = instructions.get(pc)
        if op is None or op.mode not in ("rel", "zpr") or op.mnemonic == "BRA":
            return None
        length = MODE_LENGTH[op.mode]
        return branch_target(pc, read((pc + length - 1) & WORD), length), (pc + length) & WORD

    def merged(pc: int, target: int, following: int) -> Region | None:
        """Ways to two branches of their own to the same two addresses, and the choice between those."""
        taken, fall = walk(target, nested=False), walk(following, nested=False)
        first, second = targets(taken.end), targets(fall.end)
        if first is None or second is None or taken.end == fall.end or set(first) != set(second) \
                or first[0] == first[1]:
            return None
        then = meeting(taken.end, walk(first[0]), walk(first[1]))
        if then is None:
            return None
        return Region(pc, taken, fall, then.join, (taken.end, fall.end), then)

    def region_at(pc: int) -> Region | None:
        if pc in found:
            return found[pc]
        found[pc] = None  # while being worked out: a way that comes back here stops here
        op = instructions[pc]
        length = MODE_LENGTH[op.mode]
        target = branch_target(pc, read((pc + length - 1) & WORD), length)
        following = pc + length
        region = None
        if following <= WORD:
            region = meeting(pc, walk(target), walk(following))
            if region is None or region.cost > MAX_COST:
                region = merged(pc, target, following)
            if region is not None and region.cost > MAX_COST:
                region = None
        found[pc] = region
        return region

    for pc, op in sorted(instructions.items()):
        if op is not None and op.mode in ("rel", "zpr") and op.mnemonic != "BRA":
            region_at(pc)
    return {pc: region for pc, region in found.items() if region is not None}
