"""How the machine's CPU cycle clock drives the PPU's (frame, line, dot) position.

The convention (ours; the real console powers up at an unknown CPU/PPU phase):
- At the machine cycle `origin` (the clock when the PPU was attached; 0 for a fresh machine) the
  PPU is at frame 0, line 0, dot 0.
- CPU cycle c (machine clock) begins at PPU dot floor((c - origin) * k) counted from there, with
  k = 3 dots per CPU cycle on NTSC and 3.2 on PAL (nesdev wiki "Cycle reference chart").
- A bus access in CPU cycle c sees every PPU event whose dot is <= that dot. So a flag set at
  absolute dot E is first visible to a read in cycle ceil(E / 3) (NTSC).
- Frames are numbered from 0; frame f runs from line 0 to the pre-render line (261 NTSC, 311 PAL),
  a full frame being lines x 341 dots. On NTSC, when rendering ($2001 bit 3 or 4) is on at dot 338
  of the pre-render line of an odd frame (`ODD_FRAME_DECISION_DOT`), the PPU jumps from dot 339 to dot 0 of line 0 of the next
  frame: that frame is 341 x 262 - 1 dots long (nesdev wiki "PPU frame timing"). PAL never skips.
"""

from __future__ import annotations

from retro.chips.ppu.constants import DOTS_PER_LINE, VideoStandard


def dots_at_cycle(cycle: int, origin: int, video: VideoStandard) -> int:
    """Absolute PPU dot (from frame 0, line 0, dot 0) at which CPU cycle `cycle` begins."""
    ratio = video.dots_per_cpu_cycle  # integer arithmetic: Fraction's operators cost more than the CPU step
    return (cycle - origin) * ratio.numerator // ratio.denominator


def first_cycle_seeing(dot: int, origin: int, video: VideoStandard) -> int:
    """The first CPU cycle whose accesses see an event at absolute PPU dot `dot`."""
    ratio = video.dots_per_cpu_cycle
    return origin - (-dot * ratio.denominator // ratio.numerator)


def line_and_dot(dot_in_frame: int) -> tuple[int, int]:
    return divmod(dot_in_frame, DOTS_PER_LINE)


def frame_dots(frame: int, rendering_at_skip: bool, video: VideoStandard) -> int:
    """Length of frame `frame` in dots, given whether rendering is on at the skip point."""
    skip = video.skips_odd_frame_dot and rendering_at_skip and frame % 2 == 1
    return video.dots_per_frame - (1 if skip else 0)
