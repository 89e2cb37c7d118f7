"""Cycles as raster lines and as a share of a frame, on the machines a routine's CPU runs in.

The figures follow the routine's machine (`[program] machine`, by default the CPU's: the C64 for the
6510, the NES for the 2A03, none for the 65C02; `none` names a bare CPU and gives no figures). A C64
routine is shown on the C64 (PAL 6569: 63 cycles a line, 312 lines; NTSC 6567R8: 65 and
263), a NES routine on the NES (NTSC: 341 dots a line at 3 dots per CPU cycle, 113.67 CPU cycles a
line, 262 lines; PAL: 3.2 dots per cycle, 106.56 cycles a line, 312 lines). The numbers come from
the chip constants (retro.chips.vic.constants, retro.chips.ppu.constants), where their sources are.
The CPU is assumed never stalled (no bad lines, sprite DMA or OAM DMA during the routine).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from retro.chips.ppu import constants as ppu
from retro.chips.vic import constants as vic


@dataclass(frozen=True)
class Timeline:
    key: str  # the JSON key
    label: str
    cycles_per_line: Fraction
    lines_per_frame: int

    @property
    def frame_cycles(self) -> Fraction:
        return self.cycles_per_line * self.lines_per_frame


C64_TIMELINES = tuple(Timeline(f"c64_{v.name}", f"C64 {v.name.upper()} ({v.chip})", Fraction(v.cycles_per_line), v.lines)
                      for v in (vic.PAL, vic.NTSC))
NES_TIMELINES = tuple(Timeline(f"nes_{s.name}", f"NES {s.name.upper()}", Fraction(ppu.DOTS_PER_LINE) / s.dots_per_cpu_cycle,
                               s.lines_per_frame) for s in (ppu.NTSC, ppu.PAL))
TIMELINES = {"c64": C64_TIMELINES, "nes": NES_TIMELINES}  # by machine (retro.machines.MACHINES)
DIGITS = 3


def raster_figures(machine: str, minimum: float | None, mean: float | None, maximum: float | None) -> dict:
    """{timeline key: {cycles_per_line, frame_cycles, min_lines, mean_lines, max_lines, max_frame_percent}}."""
    out = {}
    for timeline in TIMELINES.get(machine, ()):
        per_line = float(timeline.cycles_per_line)
        frame = float(timeline.frame_cycles)

        def lines(value):
            return None if value is None else round(value / per_line, DIGITS)
        out[timeline.key] = {
            "cycles_per_line": round(per_line, 2), "frame_cycles": round(frame, 2),
            "min_lines": lines(minimum), "mean_lines": lines(mean), "max_lines": lines(maximum),
            "max_frame_percent": None if maximum is None else round(100 * maximum / frame, DIGITS)}
    return out


def format_raster(machine: str, figures: dict) -> str:
    parts = []
    for timeline in TIMELINES.get(machine, ()):
        f = figures[timeline.key]
        if f["max_lines"] is None:
            continue
        parts.append(f"{timeline.label} {f['min_lines']:.2f}-{f['max_lines']:.2f} lines "
                     f"({f['max_frame_percent']:.2f}% of a frame at most)")
    return "; ".join(parts)
