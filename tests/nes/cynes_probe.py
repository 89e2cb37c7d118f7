"""Run probe cartridges (retro.analysis.nes_probe) in cynes and measure when $2002 bits appear.

Each run powers the emulated console on with one image and reads RAM after a few frames. For a
scene, the first delay at which a bit is seen is found by bisection (a flag stays set from the dot
it is raised until the pre-render line, so "seen at delay d" is monotone over the range searched).
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

from retro.analysis.nes_probe import (
    DONE_ADDRESS,
    DONE_MARK,
    MIN_DELAY,
    RESULT_ADDRESS,
    probe_image,
)
from retro.chips.ppu.constants import STATUS_SPRITE0_HIT, STATUS_VBLANK
from retro.chips.ppu.state import PpuState

MAX_FRAMES = 8
LOCAL_STEPS = 4                # a hint is trusted only after checking both sides of the boundary
SEARCH_END = 30_000            # after the next vblank flag (~28,700), before the pre-render line clears it (~31,000)


@dataclass(frozen=True)
class Measured:
    hit: bool
    hit_delay: int | None      # first delay whose read sees bit 6
    vblank_delay: int          # first delay whose read sees bit 7 (the vblank of the hit's frame)


class CynesProbe:
    def __init__(self) -> None:
        import cynes  # dev dependency
        self._nes_class = cynes.NES
        self._dir = tempfile.TemporaryDirectory(prefix="retro-cynes-")
        self.runs = 0

    def status(self, state: PpuState, delay: int) -> int:
        path = Path(self._dir.name) / "probe.nes"
        path.write_bytes(probe_image(state, delay))
        nes = self._nes_class(str(path))
        self.runs += 1
        for _ in range(MAX_FRAMES):
            nes.step(1)
            if nes[DONE_ADDRESS] == DONE_MARK:
                return nes[RESULT_ADDRESS]
            if nes.has_crashed:
                break
        raise RuntimeError(f"probe did not finish in {MAX_FRAMES} frames (delay {delay})")

    def boundary_near(self, state: PpuState, bit: int, hint: int) -> int | None:
        """The first delay seeing `bit`, found by walking from hint (None if not within a few steps)."""
        seen = bool(self.status(state, hint) & bit)
        step = -1 if seen else 1
        delay = hint
        for _ in range(LOCAL_STEPS):
            if bool(self.status(state, delay + step) & bit) != seen:
                return delay if seen else delay + step
            delay += step
        return None

    def first_delay(self, state: PpuState, bit: int, lo: int = MIN_DELAY, hi: int = SEARCH_END) -> int | None:
        """Smallest delay in [lo, hi] whose read sees `bit`, or None when even hi does not."""
        if not self.status(state, hi) & bit:
            return None
        while lo < hi:
            mid = (lo + hi) // 2
            if self.status(state, mid) & bit:
                hi = mid
            else:
                lo = mid + 1
        return lo

    def measure(self, state: PpuState, vblank_hint: int | None = None, hit_hint: int | None = None) -> Measured:
        """First delays seeing the vblank flag of the hit's frame and the hit flag.

        Hints (guesses of the answer) only save runs: every answer is checked on both sides.
        """
        vblank = self.boundary_near(state, STATUS_VBLANK, vblank_hint) if vblank_hint else None
        if vblank is None:
            vblank = self.first_delay(state, STATUS_VBLANK)
        if vblank is None:
            raise RuntimeError("the vblank flag was never seen")
        if not self.status(state, vblank) & STATUS_SPRITE0_HIT:    # the hit flag lasts until the pre-render line
            return Measured(hit=False, hit_delay=None, vblank_delay=vblank)
        hit = self.boundary_near(state, STATUS_SPRITE0_HIT, hit_hint) if hit_hint and hit_hint < vblank else None
        if hit is None:
            hit = self.first_delay(state, STATUS_SPRITE0_HIT, hi=vblank)
        return Measured(hit=True, hit_delay=hit, vblank_delay=vblank)
