"""Where the beam is: machine cycles <-> (frame, line, cycle) and pixel positions -> cycles.

Timing model (docs/vic.md):
- A device attached at machine cycle m0 starts at raster line 0, cycle 1 of frame 0. Machine cycle m
  is frame-time t = m - m0; frame = t // (lines * cycles_per_line); line and cycle (1-based, as in
  Bauer's timing diagrams) follow from the remainder.
- Cycle 1 of a line draws the X coordinates first_x .. first_x+7 ($194 on the 6569, $19C on the
  6567R8 and 6567R56A, where the raster IRQ fires) [Bauer 3.4, 3.6.1]; each cycle draws the next 8
  X coordinates, which run up to $1F7 (6569) or $1FF (6567R8, 6567R56A) and continue at 0. So
  pixel X of line L is drawn in cycle 1 + ((X - first_x) mod x_positions) // 8 of line L. The
  6567R8's 65th cycle has no X coordinate of its own in this model; the 6567R56A's 64 cycles draw
  its 512 X exactly.
- A collision at pixel X is latched COLLISION_LATCH_DELAY (4) X coordinates later than that, in
  cycle 1 + ((X + 4 - first_x) mod x_positions) // 8 (measured by the VICE test programs
  VICII/spritecollisions/*-collision-cycle; see constants.py). On the 6569 the last four X
  coordinates of a line ($190-$193) therefore latch in cycle 1 of the next line. The model
  (model.sequencer_slots, model._events) takes that cycle from the sprite sequencer's slot, which
  also counts the 6567R8's cycle that draws X $180-$187 a second time.
- "Frame time" of a latch = line * cycles_per_line + (its cycle - 1), modulo the frame. A collision
  latch bit set at frame time p is seen by a read at frame time t > p. A register write at t changes
  what is drawn from t + 1 on.
"""

from __future__ import annotations

import numpy as np

from retro.chips.vic.constants import Video


def beam_order(video: Video, x: np.ndarray | int) -> np.ndarray | int:
    """Index of X coordinate x in the drawing order of a line (0 = drawn first)."""
    return (x - video.first_x) % video.x_positions


def beam_key(video: Video, line: np.ndarray | int, x: np.ndarray | int) -> np.ndarray | int:
    """Total order of pixels as the beam draws them within one frame."""
    return line * video.x_positions + beam_order(video, x)


def position(video: Video, frame_time: int) -> tuple[int, int, int]:
    """Device time (cycles since attach) -> (frame, line, 1-based cycle in the line)."""
    frame, within = divmod(frame_time, video.frame_cycles)
    line, cycle0 = divmod(within, video.cycles_per_line)
    return frame, line, cycle0 + 1
