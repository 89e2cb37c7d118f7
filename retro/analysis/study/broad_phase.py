"""Broad phases on the 6502: which pairs of N objects a game hands to its pair test, and what that costs.

Two drivers in asm/broad/broad_phase.s, each checked by `retro check asm/broad/NAME.toml` against the
references below:
- `pairs_all` (BRUTE): every pair, n(n-1)/2 of them;
- `sweep_x` (SORT_X): an insertion sort of the objects by left edge (from the previous frame's order,
  as a game keeps it), then a sweep handing on the pairs whose X intervals overlap.

Both call `narrow` once per candidate pair. For the cost per frame the driver runs twice on each
object layout: with `narrow` as assembled (it counts the pairs: compared with `sweep_x_reference`,
a mismatch stops the run) and with `narrow` patched to a bare RTS, whose cycles are the driver's
own (its loops and one JSR per candidate) plus that RTS per candidate. The pair test's cycles, RTS
included, are then added per candidate by the per-frame model (per_frame.py), so the RTS is taken off
here: `BroadSample.cycles` is the driver without it.

Layouts: N objects on a field one byte wide; object k has shape k mod S of the S shapes given and an
X interval from the method's `x_extent` of that shape (its hitbox as far as X goes), at a random
position, moving by up to MAX_SPEED pixels per frame (bouncing at the field's edges). Only X matters
to these broad phases (the sort is along X), so a layout is the objects' left edges and widths.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from retro.errors import RunError

MAX_OBJECTS = 64  # order lives in zero page $80-$BF: 64 object numbers
BYTE = 256
RTS = 0x60  # the opcode the per-frame run patches into `narrow`
MAX_SPEED = 2  # pixels per frame an object moves along X in the generated layouts
SOURCE = ("broad", "broad_phase.s")

BRUTE = "brute"
SORT_X = "sort_x"
PHASES = (BRUTE, SORT_X)
PHASE_LABELS = {BRUTE: "every pair (brute force)", SORT_X: "sort and sweep along X"}
ENTRIES = {BRUTE: "pairs_all", SORT_X: "sweep_x"}


def rts_cycles() -> int:
    """Cycles of the RTS that ends a pair test (the timing table's figure)."""
    from retro.cpu.timing import timing_of

    return timing_of(RTS).cycles


# ---- references and cases for the specs (asm/broad/*.toml) ------------------------------------------

def pairs_all_reference(n: int) -> int:
    return n * (n - 1) // 2


def overlapping_pairs(xs: Sequence[int], ws: Sequence[int], objects: Sequence[int]) -> int:
    """Unordered pairs of the given objects whose half-open X intervals [x, x + w) share a pixel."""
    count = 0
    for i, a in enumerate(objects):
        for b in objects[i + 1:]:
            if max(xs[a], xs[b]) < min(xs[a] + ws[a], xs[b] + ws[b]):
                count += 1
    return count


def sweep_x_reference(n: int, order: Sequence[int], xs: Sequence[int], ws: Sequence[int]) -> dict:
    """The first n object numbers sorted by left edge, ties in their given order (the rest of the
    table as it was), and the number of pairs among them whose X intervals overlap."""
    first = sorted(order[:n], key=lambda o: xs[o])  # sorted() is stable
    return {"pairs": overlapping_pairs(xs, ws, first), "sorted": tuple(first) + tuple(order[n:])}


def _case(n: int, order, xs, ws) -> tuple:
    fill = list(range(n, MAX_OBJECTS))
    return (n, tuple(list(order) + fill), tuple(int(v) for v in xs), tuple(int(v) for v in ws))


def _random_layout(rng: np.random.Generator, n: int, widest: int) -> tuple[np.ndarray, np.ndarray]:
    ws = rng.integers(1, widest + 1, MAX_OBJECTS)
    xs = np.array([rng.integers(0, BYTE - w) for w in ws])  # x + w <= 255
    return xs, ws


def sweep_x_boundary() -> list[tuple]:
    cases = []
    for n in (0, 1, 2, 3, MAX_OBJECTS):
        same = [100] * MAX_OBJECTS
        cases.append(_case(n, range(n), same, [1] * MAX_OBJECTS))  # all at one x, 1 wide: every pair
        cases.append(_case(n, range(n), [0] * MAX_OBJECTS, [255] * MAX_OBJECTS))  # the whole byte each
        spread = [4 * k for k in range(MAX_OBJECTS)]
        cases.append(_case(n, range(n), spread, [4] * MAX_OBJECTS))  # touching neighbours: no pair
        cases.append(_case(n, range(n), spread, [5] * MAX_OBJECTS))  # one pixel shared: n - 1 pairs
        cases.append(_case(n, range(n - 1, -1, -1), spread, [5] * MAX_OBJECTS))  # reversed: the most shifts
        ties = [50 + (k % 3) for k in range(MAX_OBJECTS)]
        cases.append(_case(n, range(n), ties, [2] * MAX_OBJECTS))  # ties keep their order
    return cases


def sweep_x_random(rng: np.random.Generator, count: int) -> list[tuple]:
    cases = []
    for i in range(count):
        n = int(rng.integers(0, MAX_OBJECTS + 1))
        xs, ws = _random_layout(rng, n, int(rng.choice([4, 24, 64, 255])))
        kind = i % 3
        if kind == 0:
            order = rng.permutation(n)
        else:  # sorted, or nearly: a few neighbours swapped (last frame's order after a small move)
            order = np.array(sorted(range(n), key=lambda o: xs[o]))
            for _ in range(int(rng.integers(0, 4)) if kind == 1 else 0):
                if n > 1:
                    k = int(rng.integers(0, n - 1))
                    order[k], order[k + 1] = order[k + 1], order[k]
        cases.append(_case(n, order.tolist(), xs, ws))
    return cases


# ---- running the drivers ------------------------------------------------------------------------------

@lru_cache(maxsize=None)
def program():
    from retro.assembler import assemble_file
    from retro.paths import ASM_DIR

    return assemble_file(ASM_DIR.joinpath(*SOURCE))


class BroadRunner:
    """One machine with asm/broad/broad_phase.s loaded."""

    def __init__(self) -> None:
        from retro.cpu.machine import Machine

        prog = program()
        self.machine = Machine("6510")
        self.machine.load(prog)
        self.narrow = prog.symbols["narrow"]
        self.counting = self.machine.peek(self.narrow)[0]  # the first byte of the counting stub

    def run(self, phase: str, xs: Sequence[int], ws: Sequence[int], order: Sequence[int],
            counting: bool) -> tuple[int, int, list[int]]:
        """(cycles, the count register, the order table after the call)."""
        n = len(order)
        memory = {"n": [n], "order": list(order) + list(range(n, MAX_OBJECTS)),
                  "obj_x": list(xs) + [0] * (MAX_OBJECTS - n), "obj_w": list(ws) + [1] * (MAX_OBJECTS - n),
                  "narrow": [self.counting if counting else RTS], "count": [0, 0]}
        result = self.machine.call(ENTRIES[phase], memory=memory, budget=10_000_000)
        low, high = self.machine.peek("count", 2)
        return result.cycles, low | high << 8, self.machine.peek("order", n) if n else []


@dataclass(frozen=True)
class BroadSample:
    """One run of a driver on one layout: the driver's cycles (its loops and a JSR per candidate,
    not the RTS that ends each test) and the candidate pairs it handed on."""

    cycles: int
    candidates: int


def place_objects(extents: Sequence[tuple[int, int]], n: int, seed: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """(sprite X per object, velocity per object, lowest X, highest X) of the first n objects of layout
    `seed` (the layouts of n objects are the first n of the same 64, so the curves over n do not
    jump from one random layout to another): object k has extent k mod S; every interval stays
    inside one byte (x + lo >= 0, x + hi <= 255)."""
    lowest = max([0] + [-lo for lo, _ in extents])
    highest = min(BYTE - 1 - hi for _, hi in extents)
    if highest < lowest:
        raise RunError(f"an X extent of {max(hi - lo for lo, hi in extents)} pixels leaves no room in a byte")
    rng = np.random.default_rng(seed)
    xs = rng.integers(lowest, highest + 1, MAX_OBJECTS)
    speeds = rng.integers(-MAX_SPEED, MAX_SPEED + 1, MAX_OBJECTS)
    return xs[:n], speeds[:n], lowest, highest


def _intervals(extents, xs) -> tuple[list[int], list[int]]:
    left, width = [], []
    for k, x in enumerate(xs.tolist()):
        lo, hi = extents[k % len(extents)]
        left.append(x + lo)
        width.append(hi - lo)
    return left, width


def sweep_samples(extents: tuple[tuple[int, int], ...], n: int, seeds: int, frames: int) -> list[BroadSample]:
    """sweep_x on `seeds` layouts of n objects, each over `frames` frames after the first (which sorts
    the objects from their creation order: not a steady frame, not sampled). Every run's pairs and
    order are checked against sweep_x_reference."""
    runner = BroadRunner()
    rts = rts_cycles()
    samples = []
    for seed in range(seeds):
        xs, speeds, lowest, highest = place_objects(extents, n, seed)
        order = list(range(n))
        for frame in range(frames + 1):
            left, width = _intervals(extents, xs)
            expected = sweep_x_reference(n, order, left, width)
            counted_cycles, pairs, counted_order = runner.run(SORT_X, left, width, order, counting=True)
            cycles, _, bare_order = runner.run(SORT_X, left, width, order, counting=False)
            if pairs != expected["pairs"] or counted_order != list(expected["sorted"][:n]) or bare_order != counted_order:
                raise RunError(f"asm/broad/broad_phase.s sweep_x: {n} objects, layout {seed} frame {frame}: "
                               f"{pairs} pairs, the reference {expected['pairs']} (or the order differs)")
            if frame:
                samples.append(BroadSample(cycles - rts * pairs, pairs))
            order = counted_order
            moved = xs + speeds
            bounce = (moved < lowest) | (moved > highest)
            speeds = np.where(bounce, -speeds, speeds)
            xs = np.clip(xs + speeds, lowest, highest)
    return samples


def brute_sample(n: int) -> BroadSample:
    """pairs_all for n objects (its cost does not depend on where they are); its count checked."""
    runner = BroadRunner()
    _, pairs, _ = runner.run(BRUTE, [0] * n, [1] * n, list(range(n)), counting=True)
    cycles, _, _ = runner.run(BRUTE, [0] * n, [1] * n, list(range(n)), counting=False)
    if pairs != pairs_all_reference(n):
        raise RunError(f"asm/broad/broad_phase.s pairs_all: {n} objects gave {pairs} pairs, not {pairs_all_reference(n)}")
    return BroadSample(cycles - rts_cycles() * pairs, pairs)
