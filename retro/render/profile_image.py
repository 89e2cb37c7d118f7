"""A profile as a picture: one frame of the beam, a row per raster line (C64) or scanline (NES) and a
column per CPU cycle of the line, each cell in the colour of the subroutine that ran innermost then
(the legend beside it names them, with their cycles; `profile` is a retro.analysis.profile.Profile,
which render does not import); on the C64 a cell where the VIC-II held the bus
(BA low: Bad Lines, sprite DMA) is darker; cells where nothing of the run ran are left black."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from retro.render.images import label_font

# distinct colours (Kelly's 22 of maximum contrast, K. L. Kelly, "Twenty-two colors of maximum
# contrast", 1965), white and black left out; they repeat after 20 subroutines
PALETTE = [(0xF3, 0xC3, 0x00), (0x87, 0x56, 0x92), (0xF3, 0x84, 0x00), (0xA1, 0xCA, 0xF1), (0xBE, 0x00, 0x32),
           (0xC2, 0xB2, 0x80), (0x84, 0x84, 0x82), (0x00, 0x88, 0x56), (0xE6, 0x8F, 0xAC), (0x00, 0x67, 0xA5),
           (0xF9, 0x93, 0x79), (0x60, 0x4E, 0x97), (0xF6, 0xA6, 0x00), (0xB3, 0x44, 0x6C), (0xDC, 0xD3, 0x00),
           (0x88, 0x2D, 0x17), (0x8D, 0xB6, 0x00), (0x65, 0x45, 0x22), (0xE2, 0x58, 0x22), (0x2B, 0x3D, 0x26)]
NOTHING = (0, 0, 0)
BA_LOW_SHADE = 0.55  # a cell's colour times this where the VIC-II holds the bus
CELL_WIDTH, CELL_HEIGHT = 6, 2
LEGEND_WIDTH = 420
MARGIN = 8
ROW_HEIGHT = 16
MAX_LEGEND_ROWS = 40


def colour_of(index: int) -> tuple[int, int, int]:
    return NOTHING if index < 0 else PALETTE[index % len(PALETTE)]


def frame_grid(profile, frame: int) -> np.ndarray:
    """(lines, columns) of routine indices (-1: nothing of the run) of one frame of the beam."""
    beam = profile.beam
    grid = np.full((beam.lines, beam.columns), -1, dtype=np.int32)
    first, end = beam.frame_start(frame), beam.frame_start(frame + 1)
    transitions = profile.transitions
    for (start, index), (stop, _) in zip(transitions, transitions[1:]):
        lo, hi = max(start, first), min(stop, end)
        if hi <= lo or index < 0:
            continue
        cycles = np.arange(lo, hi, dtype=np.int64)
        frames, lines, columns = beam.positions(cycles)
        keep = (frames == frame) & (columns < beam.columns)
        grid[lines[keep], columns[keep]] = index
    return grid


def chosen_frame(profile, frame: int | None) -> int:
    """The frame to draw: the one asked for, else the last one the run covered whole (else its first)."""
    beam = profile.beam
    last_cycle = profile.transitions[-1][0] if profile.transitions else profile.first_cycle
    first_frame = beam.position(profile.first_cycle)[0]
    last_frame = beam.position(max(last_cycle - 1, profile.first_cycle))[0]
    if frame is not None:
        return frame
    whole = [f for f in range(first_frame, last_frame + 1)
             if beam.frame_start(f) >= profile.first_cycle and beam.frame_start(f + 1) <= last_cycle]
    return whole[-1] if whole else first_frame


def profile_image(profile, frame: int | None = None) -> Image.Image:
    """The picture of the module docstring for `frame` (default: `chosen_frame`)."""
    beam = profile.beam
    shown = chosen_frame(profile, frame)
    grid = frame_grid(profile, shown)
    colours = np.array([NOTHING] + [colour_of(i) for i in range(len(profile.order))], dtype=np.float64)
    pixels = colours[grid + 1]
    if profile.ba_low is not None:
        low = np.asarray(profile.ba_low, dtype=bool).reshape(beam.lines, beam.columns)
        pixels[low & (grid >= 0)] *= BA_LOW_SHADE
    chart = Image.fromarray(pixels.astype(np.uint8), "RGB").resize((beam.columns * CELL_WIDTH,
                                                                    beam.lines * CELL_HEIGHT), Image.NEAREST)
    height = max(chart.height, MARGIN * 2 + ROW_HEIGHT * (min(len(profile.routines), MAX_LEGEND_ROWS) + 3))
    image = Image.new("RGB", (chart.width + LEGEND_WIDTH + 3 * MARGIN, height + 2 * MARGIN), (255, 255, 255))
    image.paste(chart, (MARGIN, MARGIN))
    draw = ImageDraw.Draw(image)
    font = label_font()
    x = chart.width + 2 * MARGIN
    draw.text((x, MARGIN), f"frame {shown}: a row per {beam.unit} (0 at the top), a column per CPU cycle",
              fill=(0, 0, 0), font=font)
    note = "black: nothing of the run" + ("; darker: the VIC-II holds the bus" if profile.ba_low is not None else "")
    draw.text((x, MARGIN + ROW_HEIGHT), note, fill=(0, 0, 0), font=font)
    ranked = sorted(range(len(profile.routines)), key=lambda i: -profile.routines[i].inclusive)
    for row, i in enumerate(ranked[:MAX_LEGEND_ROWS]):
        stats = profile.routines[i]
        y = MARGIN + ROW_HEIGHT * (row + 2) + 4
        draw.rectangle((x, y + 2, x + 12, y + 12), fill=colour_of(profile.order.index((stats.address, stats.kind))))
        draw.text((x + 18, y), f"{profile.label(stats)}: {stats.calls} calls, {stats.inclusive} incl, "
                               f"{stats.exclusive} excl", fill=(0, 0, 0), font=font)
    return image
