"""What a collision method of the study is: one object that holds everything about it.

A `Method` holds
- its **accuracy rule**: `verdict(pair)`, the method's answer on every case of a pair at once
  (numpy; 1.0 hit, 0.0 no hit; an `averaged` method gives the share of grid alignments that hit).
  It must work on any subset of a pair's cases (`sub_pair`), so a caller pays only for the cases it
  looks at;
- its **6502 routine** by spec (`routine`: a built-in name from asm/ or a spec path) and, when the
  method is meant to be used with values prepared once per object, the preparation routine
  (`prepare`);
- how a case (a shape pair and an offset) becomes the routine's **inputs**: `case_maker(pair)`
  returns a function from case index to the routine's inputs by name (the spec's input names); the
  spec alone knows where each value goes;
- its **host timing**: `host_calls(pair, indices)`, one zero-argument call per case running the
  method's Python reference;
- its **label**, the sentence that states its rule, its chart colour and marker, and what its cycle
  figure counts (`counted`);
- its limits: `hardware` (it needs the VIC-II's collision latch), `machines` (where it exists: the
  C64, the NES), `advice_note(sprites)` (why it cannot serve a scene);
- what it costs per frame (per_frame.py): `prepare_per` (its preparation runs once per object, or
  once per pair of object kinds), `once_per_frame` (one call a frame for all objects, as the latch
  read; then at most `max_objects`), and `x_extent(shape)`, the X interval outside which it never
  reports a hit (a broad phase along X must hand on every pair whose intervals meet).

The chart, the stability study, the advisor, the report and the cost runs iterate over method
objects; none of them looks at a method's key to decide what to do.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from retro.analysis.check.engines import batched
from retro.analysis.study.corpus import Pair
from retro.fileio import cached_reads

OBJECT = "object"  # Method.prepare_per: the preparation runs once per object and frame
KIND_PAIR = "kind_pair"  # ... or once per pair of object kinds (a radius sum); charged every frame here
PREPARE_SCOPES = (OBJECT, KIND_PAIR)

ORIGIN = 64  # shape a's sprite box sits at (64, 64): every coordinate of the corpus stays in 0..255

Case = dict  # a routine's inputs by the spec's input names


def sub_pair(pair: Pair, indices) -> Pair:
    """The same shape pair restricted to some of its cases (in the order given)."""
    idx = np.asarray(indices, dtype=np.intp)
    return replace(pair, dx=pair.dx[idx], dy=pair.dy[idx], overlap=pair.overlap[idx])


@cached_reads(maxsize=None)  # a cached spec still names its files as the command's inputs
def routine_spec(name_or_path: str):
    """The Routine of a spec (built-in name or path), read once per process."""
    from retro.routines.registry import get

    return get(name_or_path)


def routine_runner(name_or_path: str):
    """A freshly loaded RoutineRunner for a routine spec (each session has its own machine)."""
    from retro.routines.runner import RoutineRunner

    return RoutineRunner(routine_spec(name_or_path))


# A pair's calls run on the engine the commands' --engine names, by the check's one rule
# (retro.analysis.check.engines.batched): "auto" takes the batched core from BATCH_FROM calls on (a
# method's calls need no agreement run, so the batched core pays from far fewer calls than in a check).
BATCH_FROM = 256


class Session:
    """A method's 6502 routine loaded and ready for the cases of one pair."""

    def run(self, index: int) -> tuple[bool, int]:
        """(the routine's answer: hit or not, cycles of the call) on case `index` of the pair."""
        raise NotImplementedError

    def run_many(self, indices: list[int], engine: str = "auto") -> tuple[list[bool], list[int]]:
        """`run` on many cases: (answers, cycles) in the order given (on Machine, whatever `engine`)."""
        results = [self.run(index) for index in indices]
        return [r[0] for r in results], [r[1] for r in results]

    def expected(self, index: int) -> bool:
        """The answer the routine must give on this case, when it is not the method's verdict (a
        method whose verdict is averaged over grid alignments checks the alignment the call used)."""
        raise NotImplementedError("an averaged method's session says what each call must answer")


class RoutineSession(Session):
    """The usual session: the method's case maker gives the logical case, the spec's runner calls."""

    def __init__(self, method: "Method", pair: Pair) -> None:
        from retro.errors import InputError

        self.case = method.case_maker(pair)
        self.runner = routine_runner(method.routine)
        self.hit = method.hit_output
        self.names = self.runner.routine.input_names
        if pair.cases:
            given = set(self.case(0))
            if given != set(self.names):
                raise InputError(f"{self.runner.routine.spec_path}: inputs: method {method.key} gives "
                                 f"{', '.join(sorted(given))}; the routine takes {', '.join(self.names)}")

    def run(self, index: int) -> tuple[bool, int]:
        case = self.case(index)
        outputs, cycles = self.runner.run(tuple(case[name] for name in self.names))
        return bool(outputs[self.hit]), cycles

    def run_many(self, indices: list[int], engine: str = "auto") -> tuple[list[bool], list[int]]:
        """On the batched core when the engine rule says so; a call that does not return is run again
        on Machine, whose error names it."""
        if not indices or not batched(engine, len(indices), self.runner.batchable, BATCH_FROM):
            return super().run_many(indices)
        cases = [self.case(index) for index in indices]
        columns = [np.asarray([case[name] for case in cases], dtype=np.int64) for name in self.names]
        outcome = self.runner.run_batch(columns)
        if outcome.error.any():
            return super().run_many(indices)
        hit = outcome.outputs[self.hit]
        answers = hit.any(axis=1) if hit.ndim == 2 else hit != 0
        return answers.tolist(), outcome.cycles.tolist()


@dataclass(frozen=True, kw_only=True)
class Method:
    key: str
    label: str
    rule: str  # what exactly is tested, one sentence for the docs and the CSV
    colour: str = "#333333"
    marker: str = "o"
    routine: str | None = None  # the test's spec: a built-in name (asm/NAME.toml) or a spec path
    prepare: str | None = None  # the once-per-object preparation routine's spec, if the method has one
    hit_output: int = 0  # which output of the routine is the answer (non-zero = hit)
    counted: str = ""  # what the cycle figure covers
    hardware: bool = False  # needs the VIC-II's collision hardware (not on the NES, not past 8 sprites)
    averaged: bool = False  # the verdict is a share of grid alignments, not a 0/1 answer
    max_cost_samples: int | None = None  # a cap on measured calls per pair when a call is costly to set up
    origin: str = ""  # where the method is defined (a module, or the user's TOML file)
    machines: tuple[str, ...] = ("c64", "nes")  # where the method exists (the latch: the C64's VIC-II only)
    prepare_per: str = OBJECT  # the `prepare` routine runs once per object and frame, or per KIND_PAIR
    once_per_frame: bool = False  # one call a frame answers for every object (the latch read), not one per pair
    max_objects: int | None = None  # the most objects it can serve (hardware sprites)

    @property
    def host_only(self) -> bool:
        """No 6502 routine: no cycles (SAT)."""
        return self.routine is None

    # ---- the accuracy rule ----------------------------------------------------------------------

    def verdict(self, pair: Pair) -> np.ndarray:
        raise NotImplementedError

    # ---- the 6502 routine -----------------------------------------------------------------------

    def case_maker(self, pair: Pair) -> Callable[[int], Case]:
        """Case index -> the routine's inputs by name (the spec's input names)."""
        raise NotImplementedError(f"{self.key}: no routine inputs")

    def session(self, pair: Pair) -> Session:
        return RoutineSession(self, pair)

    def unmeasurable(self, pair: Pair) -> str:
        """Why the routine cannot take this pair ("" when it can): its cycles are then not measured."""
        return ""

    def size(self) -> tuple[int, int]:
        """(bytes of code, bytes of lookup tables) of the routine, as `retro cycles` counts them."""
        size = routine_runner(self.routine).size()
        return size.code_bytes, size.table_bytes

    # ---- host timing and limits -----------------------------------------------------------------

    def host_calls(self, pair: Pair, indices: list[int]) -> list[Callable[[], object]]:
        """One zero-argument call per case running the method's Python reference. By default the
        method's own verdict on that one case."""
        return [lambda one=sub_pair(pair, [i]): self.verdict(one) for i in indices]

    def advice_note(self, sprites: int) -> str:
        """Why the method cannot serve a scene with this many sprites ("" when it can)."""
        return ""

    def x_extent(self, shape) -> tuple[int, int]:
        """(lo, hi): the half-open X interval, in the sprite's pixels (0 = its left column), outside
        which the method never reports a hit: two objects whose intervals do not meet never collide
        under its rule. By default the sprite box (the corpus has no case with the boxes apart)."""
        return 0, shape.width
