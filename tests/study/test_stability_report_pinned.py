"""The stability study's scenarios and its report, pinned against the figures docs/study.md states
("Stability: where each method breaks") and figures worked by hand; tests/study/test_stability_pinned.py
pins the rows the report is made from.

- the full run's speeds reach past every documented safe speed (the full box is safe up to 47
  px/frame, the fitted circles up to 27, the exact methods 4, 5, 7, 11 for walls of 1, 2, 4, 8 px);
- the disc of the edge cases is the disc the docs describe (fitted r = 8), counted pixel by pixel;
- the routines across 255/256 agree with the plain overlap on all 3,136 / 6,400 pairs;
- the Markdown report shows those figures in the right columns: tunnelling safe speeds by hand,
  the wrap counts from a second computation (bit sets, docs: 2,044 on PAL and 1,938 on NTSC for the
  9-bit test), the edge verdicts and the latch reads by hand, the range rows as given.
"""

from __future__ import annotations

import numpy as np
import pytest

import independent as ind
from retro.analysis.study.corpus import load_shapes
from retro.analysis.study.methods import BUILTIN
from retro.analysis.study.stability import charts, edges, ranges, run, tunnelling, wrap

EXACT = "tight/tight_edges/sprite_edges/pixel/latch/sat"
EXACT_SAFE = [t + 4 - 1 for t in (1, 2, 4, 8)]  # T + L - 1 positions, L = 4 (the bullet): 4, 5, 7, 11
BOX_POSITIONS = 24 + 24 - 1  # the full sprite boxes overlap at 47 integer offsets
DOCS_CIRCLE_SAFE = 27  # docs/study.md: "The fitted circles (safe up to 27 px/frame)"
DOCS_WRAP_9BIT = {"pal": 2044, "ntsc": 1938}  # docs/study.md: software and chip disagree in these X pairs


@pytest.fixture(scope="module")
def bullet():
    return load_shapes(["bullet"])[0]


def test_the_scenarios_are_the_documented_ones(bullet):
    """docs/study.md: a 4x4 bullet, walls 1-8 px thick (1, 2, 4, 8), two full sprites at every pair of
    the 512 X register values, edge cases touching / sharing a column / one pixel apart (dx 24, 23, 25)."""
    assert ind.bounds(bullet.mask) == (10, 8, 14, 12) and int(bullet.mask.sum()) == 16
    assert tunnelling.THICKNESSES == (1, 2, 4, 8)
    for t in tunnelling.THICKNESSES:
        mask = tunnelling.wall(t).mask
        assert mask.shape == (21, 24) and int(mask.sum()) == 21 * t
        assert list(np.flatnonzero(mask[0])) == list(range((24 - t) // 2, (24 - t) // 2 + t))  # centred
    assert wrap.X_RANGE == 512
    assert list(edges.BOX_CASES.values()) == [24, 23, 25]


def test_the_full_run_reaches_past_every_documented_safe_speed(bullet):
    """A safe speed can only be found below the highest speed tried: the full run must find the box's
    47 (it misses from 48 px/frame on), the circles' 27, and the exact methods' 4, 5, 7, 11."""
    assert run.FULL_SPEEDS[0] == 1 and list(run.FULL_SPEEDS) == list(range(1, max(run.FULL_SPEEDS) + 1))
    table = tunnelling.tunnelling_table(bullet, speeds=run.FULL_SPEEDS)
    assert [tunnelling.safe_speed(table, "box", t) for t in tunnelling.THICKNESSES] == [BOX_POSITIONS] * 4
    assert [tunnelling.safe_speed(table, "circle/circle_r", t) for t in tunnelling.THICKNESSES] == [DOCS_CIRCLE_SAFE] * 4
    assert [tunnelling.safe_speed(table, EXACT, t) for t in tunnelling.THICKNESSES] == EXACT_SAFE
    # the circles' 27 from the independent fit: the positions where the fitted circles overlap
    wall = tunnelling.wall(1)
    circles = ind.circle_hits(ind.smallest_circle(wall.mask), ind.smallest_circle(bullet.mask),
                              [(dx, 0) for dx in range(-60, 61)])
    assert sum(circles) == DOCS_CIRCLE_SAFE


def test_the_edge_disc_is_a_radius_7_disc():
    """Pixels within distance 7 of (12, 10): per column x - 12 = 0, +-1, ..., +-7 the rows within
    sqrt(49 - dx^2): 15, 13, 13, 13, 11, 9, 7, 1 -> 15 + 2 * 67 = 149 pixels, a 15x15 box; its
    smallest enclosing circle has r = 8 after rounding up (docs: fitted r = 8)."""
    disc = edges.disc().mask
    assert int(disc.sum()) == 149
    assert ind.bounds(disc) == (5, 3, 20, 18)
    assert [int(disc[:, 12 + dx].sum()) for dx in range(8)] == [15, 13, 13, 13, 11, 9, 7, 1]
    assert ind.smallest_circle(disc)[2] == 8


def test_the_routines_agree_across_255_256_on_every_pair():
    """docs/study.md: aabb8 (x 200..255) and aabb_sprite (9-bit x 220..299) agree with the plain
    overlap |x1 - x2| < 24 on all 56^2 = 3,136 / 80^2 = 6,400 pairs; pairs 24 apart are the edge."""
    rows = {r.routine: r for r in ranges.wrap_routine_rows(reduced=False)}
    assert (rows["aabb8"].cases, rows["aabb8"].mismatches) == (3136, 0)
    assert (rows["aabb_sprite"].cases, rows["aabb_sprite"].mismatches) == (6400, 0)


# ---- the report ---------------------------------------------------------------------------------

def _chip_bits(video) -> list[int]:
    """Per X register value, the screen X coordinates a full sprite covers, as the bits of an int."""
    from retro.chips.vic.constants import REG_SPRITE_X0, REG_SPRITE_X_MSB
    from retro.chips.vic.model import VicState, placement

    registers = bytearray(wrap.REGISTER_COUNT)
    registers[wrap.REG_SPRITE_ENABLE] = 1
    data = (b"\xff" * wrap.SPRITE_BYTES,) + (bytes(wrap.SPRITE_BYTES),) * (wrap.SPRITE_COUNT - 1)
    out = []
    for x in range(512):
        registers[REG_SPRITE_X0], registers[REG_SPRITE_X_MSB] = x & 0xFF, x >> 8
        place = placement(VicState(video=video, registers=bytes(registers), sprite_data=data), 0)
        out.append(0 if place is None else sum(1 << int(v) for v in set(np.atleast_1d(place.xs).tolist())))
    return out


def _wrap_counts(video, bits: int) -> tuple[int, int]:
    """(software says hit and the chip shows none, the chip shows one and software says none)."""
    chip = _chip_bits(video)
    mask = (1 << bits) - 1
    software_only = hardware_only = 0
    for xa in range(512):
        for xb in range(512):
            software = abs((xa & mask) - (xb & mask)) < 24
            hardware = chip[xa] & chip[xb] != 0
            software_only += software and not hardware
            hardware_only += hardware and not software
    return software_only, hardware_only


STUB_RANGES = [ranges.RangeRow("circle", "inside the stated domain (r1 + r2 <= 255)", 1000, 0, "exact"),
               ranges.RangeRow("circle", "cases breaking r1 + r2 <= 255", 700, 31, "needed: the routine is wrong there")]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """The reduced report, its arithmetic-range part given (that search is tested on its own)."""
    out = tmp_path_factory.mktemp("stability")
    patch = pytest.MonkeyPatch()
    patch.setattr(ranges, "range_rows", lambda reduced=False, progress=None, engine="auto": STUB_RANGES)
    try:
        output = run.run_stability(out, reduced=True)
    finally:
        patch.undo()
    return output, (out / "stability.md").read_text()


def _rows(text: str, first_cell: str) -> list[list[str]]:
    return [[c.strip() for c in line.strip("|").split("|")] for line in text.splitlines()
            if line.startswith(f"| {first_cell} |")]


def test_the_report_tunnelling_table(report):
    """Safe speeds by hand: T + 3 for the exact methods, the box's 47 and the circles' 27 capped at
    the highest speed the reduced run tries, and the swept test never misses."""
    _, text = report
    top = max(run.REDUCED_SPEEDS)
    assert f"tested up to {top})" in text
    expected = {EXACT: EXACT_SAFE, "box": [min(BOX_POSITIONS, top)] * 4,
                "circle/circle_r": [min(DOCS_CIRCLE_SAFE, top)] * 4, tunnelling.SWEPT: [top] * 4}
    for group, speeds in expected.items():
        (row,) = _rows(text, charts.group_label(group, BUILTIN))
        assert row[1:] == [str(s) for s in speeds], group


@pytest.mark.parametrize("video", [wrap.PAL, wrap.NTSC], ids=["pal", "ntsc"])
def test_the_report_wrap_table(report, video):
    output, text = report
    rows = _rows(text, video.name.upper())
    for bits, name in ((8, "8-bit X (ignores $D010)"), (9, "9-bit X, no wrap (aabb_sprite)")):
        software_only, hardware_only = _wrap_counts(video, bits)
        if bits == 9:
            assert software_only + hardware_only == DOCS_WRAP_9BIT[video.name]
        (row,) = [r for r in rows if r[1] == name]
        assert row[2:4] == [str(software_only), str(hardware_only)], name
    if video is wrap.PAL:
        assert any(line.startswith("wrap: on PAL a 9-bit box test disagrees with the chip in 2044 of 262,144")
                   for line in output.lines), output.lines


def test_the_report_edge_latch_and_range_tables(report):
    _, text = report
    # two full sprites touching / sharing a column / one pixel apart: the chip says no / hit / no;
    # the 8x8 tile cells of boxes 24, 23, 25 px apart are shared in 7, 8, 6 of the 8 x alignments
    (header,) = _rows(text, "test")[:1]
    assert header[1:4] == list(edges.BOX_CASES)
    assert _rows(text, "VIC-II model ($D01E)")[0][1:4] == ["no", "hit", "no"]
    assert _rows(text, "rule: tile cells (8x8)")[0][1:4] == ["hit in 87.5% of alignments", "hit",
                                                            "hit in 75.0% of alignments"]
    # the multiplexer read once a frame at line 260 gets the player/enemy A bits, %11, both frames
    (row,) = _rows(text, "multiplexed sprite, one read per frame")
    assert row[2] == "frame 0 line 260: $03; frame 1 line 260: $03" and row[4] == "misattributed"
    (row,) = _rows(text, "two readers in one frame")
    assert row[2] == "frame 0 line 100: $03; frame 0 line 260: $00; frame 1 line 100: $03; frame 1 line 260: $00"
    assert _rows(text, "circle") == [["circle", r.searched, str(r.cases), str(r.wrong), r.domain] for r in STUB_RANGES]
