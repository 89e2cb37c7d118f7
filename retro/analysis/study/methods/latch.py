"""The hardware latch: both sprites' bits in the VIC-II's $D01E after one frame (retro.chips.vic, see
retro/analysis/study/latch.py). Exact per pixel; with more than two sprites its bits cannot say
which pair collided (the stability study's latch pitfalls). Its routine, asm/latch_test.s, reads the
latch through the VIC-II bus device; it has no spec because it needs a chip behind $D01E."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from retro.analysis.study.corpus import Pair
from retro.analysis.study.methods.base import Method, Session
from retro.chips.vic.constants import SPRITE_COUNT
from retro.paths import ASM_DIR

SOURCE = "latch_test.s"
ENTRY = "latch_test"


@lru_cache(maxsize=None)
def _program():
    from retro.assembler import assemble_file

    return assemble_file(ASM_DIR / SOURCE)


class LatchSession(Session):
    """One machine with a VIC-II device; each case gets a device with that case's frame drawn."""

    def __init__(self, pair: Pair) -> None:
        from retro.analysis.study.latch import latch_machine

        self.pair = pair
        self.machine, self.prepare = latch_machine(_program())

    def run(self, index: int) -> tuple[bool, int]:
        self.prepare(self.pair, index)
        result = self.machine.call(ENTRY, memory={"latch_bits": [0b11]})
        return bool(result.flags["C"]), result.cycles


@dataclass(frozen=True, kw_only=True)
class LatchMethod(Method):
    def verdict(self, pair: Pair) -> np.ndarray:
        from retro.analysis.study.latch import latch_verdicts

        return latch_verdicts(pair)

    def session(self, pair: Pair) -> Session:
        return LatchSession(pair)

    def size(self) -> tuple[int, int]:
        return len(_program().code), 0

    def host_calls(self, pair: Pair, indices: list[int]):
        from retro.analysis.study.latch import frame_latch

        return [lambda dx=int(pair.dx[i]), dy=int(pair.dy[i]): frame_latch(pair, dx, dy) for i in indices]

    def x_extent(self, shape) -> tuple[int, int]:
        from retro.analysis.study.fits import tight_box

        x0, _, x1, _ = tight_box(shape.mask)
        return x0, x1

    def advice_note(self, sprites: int) -> str:
        if sprites > SPRITE_COUNT:
            return f"{sprites} objects: more than the VIC-II's {SPRITE_COUNT} sprites (without a multiplexer)"
        if sprites != 2:
            return f"{sprites} sprites: $D01E's bits cannot say which pair collided"
        return ""


LATCH = LatchMethod(
    key="latch", label="VIC-II latch $D01E", colour="#17becf", marker="^", routine=ENTRY, hardware=True,
    machines=("c64",), once_per_frame=True, max_objects=SPRITE_COUNT,
    # each measured call needs the case's whole frame drawn by the VIC-II model, and the routine is
    # straight-line code (19 cycles whatever the latch holds): a sample per pair is enough
    max_cost_samples=192,
    rule="both sprites' bits set in $D01E after the frame (exact pixels, but not which pair or when)",
    counted="one LDA $D01E (read and clear) with the copy kept for other pairs, and the test of one pair's two "
            "bits; once per frame, not per pair of objects", origin=__name__)
