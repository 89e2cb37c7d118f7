"""Every stability scenario and its figure, against values derived by hand or a second computation.

- tunnelling: a 4x4 bullet through a wall T px thick crosses n integer positions where a method
  says "hit", n contiguous, so a share max(0, 1 - n / v) of the start phases misses; n by hand for
  the boxes (47 for the full 24-px sprite boxes, T + 3 for a 4 px box through T px) and from the
  independently fitted circles for the circle methods;
- edge conventions: by hand for two full sprites touching, sharing a column, one pixel apart, and
  from the independent rules for the discs;
- coordinate wrap: the software tests by arithmetic, the chip's answer as pixel sets of the model's
  placement of each X (a set intersection per pair, not the study's matrix product);
- latch pitfalls: the register values a program reads, by reasoning about clear-on-read;
- the figures: the data the charts draw is the data above.
"""

from __future__ import annotations

import numpy as np
import pytest

import independent as ind
from retro.analysis.study.corpus import load_shapes
from retro.analysis.study.methods import BUILTIN, method
from retro.analysis.study.stability import charts, edges, latch_pitfalls, tunnelling, wrap

SPEEDS = tuple(range(1, 25))


@pytest.fixture(scope="module")
def bullet():
    return load_shapes(["bullet"])[0]


@pytest.fixture(scope="module")
def tunnel(bullet):
    return tunnelling.tunnelling_table(bullet, speeds=SPEEDS)


def _hit_positions(key: str, bullet, thickness: int) -> int:
    """n: integer positions along the line where the method says hit (by hand or independently)."""
    assert ind.bounds(bullet.mask) == (10, 8, 14, 12)  # a 4x4 block: its tight box is the shape
    if key == "box":
        return 24 + 24 - 1  # the full sprite boxes of the wall and the bullet
    if key in ("circle", "circle_r"):
        wall = tunnelling.wall(thickness)
        ca, cb = ind.smallest_circle(wall.mask), ind.smallest_circle(bullet.mask)
        dy = 0  # wall rows 0-20 (middle 10), bullet rows 8-11 (middle 9.5 -> 10 - 10 = 0)
        return sum(ind.circle_hits(ca, cb, [(dx, dy) for dx in range(-60, 61)]))
    return thickness + 4 - 1  # every exact-for-rectangles method: tight boxes, pixels, latch, hull


def test_tunnelling_groups_by_hand(tunnel, bullet):
    """The bullet and the wall are rectangles, so every method exact on rectangles answers alike. The
    bullet travels through the wall's middle rows: its rows 8-11 on the wall's 0-20, dy = 0."""
    assert tunnelling._row_offset(bullet, tunnelling.wall(1)) == 0
    groups = list(dict.fromkeys(r.method for r in tunnel))
    assert groups == ["box", "tight/tight_edges/sprite_edges/pixel/latch/sat", "circle/circle_r", tunnelling.SWEPT]


def test_tunnelling_miss_rates(tunnel, bullet):
    for r in tunnel:
        if r.method == tunnelling.SWEPT:
            assert r.miss_rate == 0
            continue
        n = _hit_positions(r.method.split("/")[0], bullet, r.thickness)
        assert r.miss_rate == pytest.approx(max(0.0, 1 - n / r.speed)), r


def test_tunnelling_safe_speeds_by_hand(tunnel):
    exact = "tight/tight_edges/sprite_edges/pixel/latch/sat"
    assert [tunnelling.safe_speed(tunnel, exact, t) for t in tunnelling.THICKNESSES] == [4, 5, 7, 11]
    assert [tunnelling.safe_speed(tunnel, "box", t) for t in tunnelling.THICKNESSES] == [24] * 4  # never misses up to 24
    assert [tunnelling.safe_speed(tunnel, tunnelling.SWEPT, t) for t in tunnelling.THICKNESSES] == [24] * 4


def test_tunnelling_figure_draws_the_rows(tunnel):
    fig = charts.tunnelling_figure(tunnel, "bullet", BUILTIN)
    axes = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in axes] == [f"obstacle {t} px thick" for t in tunnelling.THICKNESSES]
    for ax, t in zip(axes, tunnelling.THICKNESSES):
        lines = {line.get_label(): line for line in ax.get_lines()}
        assert len(lines) == 4
        for group in dict.fromkeys(r.method for r in tunnel):
            line = lines[charts.group_label(group, BUILTIN)]
            rows = sorted((r for r in tunnel if r.method == group and r.thickness == t), key=lambda r: r.speed)
            assert list(line.get_xdata()) == list(SPEEDS)
            assert list(line.get_ydata()) == pytest.approx([100 * r.miss_rate for r in rows])
    assert charts.group_label("circle/circle_r", BUILTIN) == "fitted circle (and circle_r)"


# ---- edge conventions ------------------------------------------------------------------------------

NO, HIT = 0.0, 1.0
BOXES = list(edges.BOX_CASES)  # touching, sharing one column, one pixel apart


@pytest.fixture(scope="module")
def edge_rows():
    return {(r.case, r.test): r.hit for r in edges.edge_table()}


def test_box_edges_by_hand(edge_rows):
    """Two full sprites: touching (dx = 24) share no pixel, dx = 23 shares a column, dx = 25 leaves a
    gap. Every exact test and every box says no / hit / no; the full box and circle methods still say
    hit where they enclose empty space (the fitted circle of a full 24x21 block has r = 16: two of
    them reach 32 px); the tile cells are shared in 7/8, 8/8 and 6/8 of the x alignments."""
    expected = {
        "retro.geometry aabb_overlap": (NO, HIT, NO), "retro.geometry sat (boxes as polygons)": (NO, HIT, NO),
        "pixel masks (retro.geometry.masks)": (NO, HIT, NO), "VIC-II model ($D01E)": (NO, HIT, NO),
        "rule: sprite box AABB": (NO, HIT, NO), "rule: tight hitbox AABB": (NO, HIT, NO),
        "rule: tight hitbox, prepared edges": (NO, HIT, NO), "rule: tight hitbox, 9-bit sprite edges": (NO, HIT, NO),
        "rule: fitted circle": (HIT, HIT, HIT), "rule: fitted circle, radius sum prepared": (HIT, HIT, HIT),
        "rule: tile cells (8x8)": (7 / 8, 1.0, 6 / 8), "rule: software pixel-perfect": (NO, HIT, NO),
        "rule: VIC-II latch $D01E": (NO, HIT, NO), "rule: SAT on convex hull": (NO, HIT, NO),
    }
    for test, values in expected.items():
        assert tuple(edge_rows[(case, test)] for case in BOXES) == values, test
    assert ind.smallest_circle(np.ones((21, 24), dtype=bool))[2] == 16


def test_every_routine_answers_as_its_rule_on_the_edges(edge_rows):
    for m in BUILTIN:
        if m.host_only or m.averaged:
            assert not any(test == f"6502 {m.routine} ({m.key})" for _, test in edge_rows)
            continue
        for (case, test), hit in edge_rows.items():
            if test == f"rule: {m.label}":
                assert edge_rows[(case, f"6502 {m.routine} ({m.key})")] == hit, (m.key, case)


def test_circle_edges(edge_rows):
    """Discs with fitted r = 8: tangent at (16, 0) (d^2 = 256 = (2r)^2), just inside at (15, 5)
    (d^2 = 250, the largest sum of two squares below 256 with dy <= dx), apart at (17, 0)."""
    disc = edges.disc()
    cx, cy, r = ind.smallest_circle(disc.mask)
    assert r == 8 and edges.inside_offset(8) == (15, 5)
    cases = {f"{name} at {offset}, r = 8": offset for name, offset in
             [(edges.TANGENT, (16, 0)), (edges.INSIDE, (15, 5)), (edges.APART, (17, 0))]}
    offsets = list(cases.values())
    circle = ind.circle_hits((cx, cy, r), (cx, cy, r), offsets)
    assert circle == [False, True, False]
    box = ind.box_hits(ind.bounds(disc.mask), ind.bounds(disc.mask), offsets)
    exact = ind.pixel_hits(disc.mask, disc.mask, offsets)
    expected = {"retro.geometry circle_overlap": circle, "rule: fitted circle": circle,
                "rule: fitted circle, radius sum prepared": circle, "rule: tight hitbox AABB": box,
                "rule: software pixel-perfect": exact, "rule: VIC-II latch $D01E": exact,
                "rule: SAT on convex hull": ind.hull_hits(disc.mask, disc.mask, offsets),
                "rule: sprite box AABB": [True] * 3,
                "rule: tile cells (8x8)": ind.tile_shares(ind.bounds(disc.mask), ind.bounds(disc.mask), offsets)}
    for test, values in expected.items():
        assert [edge_rows[(case, test)] for case in cases] == pytest.approx([float(v) for v in values]), test


def test_swept_edges_by_hand(edge_rows):
    """Arriving exactly at touching (tangency) at the end of the frame is no contact."""
    assert edge_rows[("box moving into touching at t = 1", "retro.geometry swept_aabb")] == NO
    assert edge_rows[("circle moving into tangency at t = 1", "retro.geometry swept_circle")] == NO


def test_edges_markdown_shows_every_test_and_case(edge_rows):
    from retro.analysis.study.stability.run import edges_markdown

    text = edges_markdown(edges.edge_table())
    assert "hit in 87.5% of alignments" in text and "| 6502 aabb8 (tight) | no | hit | no |" in text


# ---- coordinate wrap -------------------------------------------------------------------------------

def _chip_pixels(video) -> list[frozenset[int]]:
    """The screen X coordinates a full sprite covers at each X register value (the model's placement)."""
    from retro.chips.vic.constants import REG_SPRITE_X0, REG_SPRITE_X_MSB
    from retro.chips.vic.model import placement

    registers = bytearray(wrap.REGISTER_COUNT)
    registers[wrap.REG_SPRITE_ENABLE] = 1
    data = (b"\xff" * wrap.SPRITE_BYTES,) + (bytes(wrap.SPRITE_BYTES),) * (wrap.SPRITE_COUNT - 1)
    out = []
    for x in range(512):
        registers[REG_SPRITE_X0], registers[REG_SPRITE_X_MSB] = x & 0xFF, x >> 8
        place = placement(wrap.VicState(video=video, registers=bytes(registers), sprite_data=data), 0)
        out.append(frozenset() if place is None else frozenset(int(v) for v in np.atleast_1d(place.xs)))
    return out


@pytest.mark.parametrize("video", [wrap.PAL, wrap.NTSC], ids=["pal", "ntsc"])
def test_wrap_counts(video):
    rows, maps = wrap.wrap_table()
    chip = _chip_pixels(video)
    for bits, name in ((8, "8-bit X (ignores $D010)"), (9, "9-bit X, no wrap (aabb_sprite)")):
        row = next(r for r in rows if r.video == video.name and r.test == name)
        mask = (1 << bits) - 1
        software_only = hardware_only = 0
        for xa in range(512):
            for xb in range(512):
                software = abs((xa & mask) - (xb & mask)) < 24
                hardware = not chip[xa].isdisjoint(chip[xb])
                software_only += software and not hardware
                hardware_only += hardware and not software
        assert (row.software_only, row.hardware_only, row.cases) == (software_only, hardware_only, 512 * 512), name
        category = maps[(video.name, name)]
        assert int((category == wrap.SOFTWARE_ONLY).sum()) == software_only


def test_wrap_by_hand():
    """Arithmetic only: the 8-bit test says hit for X = 0 and X = 256 (same low byte), the 9-bit test
    does not; on the PAL chip X $1F8-$1FF shows no sprite, so even two sprites at the same such X never
    collide there."""
    rows, maps = wrap.wrap_table()
    eight = maps[("pal", "8-bit X (ignores $D010)")]
    nine = maps[("pal", "9-bit X, no wrap (aabb_sprite)")]
    assert eight[0, 256] == wrap.SOFTWARE_ONLY and nine[0, 256] == wrap.AGREE_MISS
    assert nine[0x1F8, 0x1F8] == wrap.SOFTWARE_ONLY
    assert nine[100, 123] == wrap.AGREE_HIT and nine[100, 124] == wrap.AGREE_MISS


def test_wrap_figure_draws_the_maps():
    rows, maps = wrap.wrap_table()
    fig = charts.wrap_figure(maps, rows)
    for ax, key in zip(fig.axes, maps):
        assert np.array_equal(np.asarray(ax.images[0].get_array()), maps[key])
        r = next(r for r in rows if (r.video, r.test) == key)
        assert f"software only {r.software_only}, chip only {r.hardware_only}" in ax.get_title()


# ---- latch pitfalls ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def pitfalls():
    ship, ball = load_shapes(["ship", "ball"])
    return {p.kind: p for p in latch_pitfalls.pitfalls(ship, ball)}


def test_latch_pitfalls_by_hand(pitfalls):
    """Sprites 0 and 1 overlapping set bits 0 and 1: $03. A read returns what was drawn since the last
    read and clears it: the first reader of a frame gets $03, a second one in the same frame 0; a read
    above the overlap gets the previous frame's bits (0 in frame 0, then $03); two overlapping pairs
    set four bits ($0F), which pair the six pairs of set bits, four of them false."""
    assert [(r.frame, r.line, r.value) for r in pitfalls["misattributed"].reads] == [(0, 260, 3), (1, 260, 3)]
    assert [(r.frame, r.line, r.value) for r in pitfalls["missed"].reads] == [(0, 100, 3), (0, 260, 0),
                                                                               (1, 100, 3), (1, 260, 0)]
    assert [(r.frame, r.line, r.value) for r in pitfalls["late"].reads] == [(0, 100, 0), (1, 100, 3), (2, 100, 3)]
    assert [r.value for r in pitfalls["false pairs"].reads] == [0x0F]
    assert "[(0, 2), (0, 3), (1, 2), (1, 3)]" in pitfalls["false pairs"].conclusion
    assert "4 of them" in pitfalls["false pairs"].conclusion
    assert "no overlap" in pitfalls["misattributed"].truth  # enemy B, after the move, touches nothing


def test_latch_read_lines_are_where_the_scenarios_need_them(pitfalls):
    """The overlaps start above line 100 (read_twice) and below it (read_before_drawn): the lines the
    scenarios name are consistent with the positions they place (y = 70/74 and 170/174, plus the
    first visible sprite line's offset)."""
    import re

    missed = int(re.search(r"from line (\d+)", pitfalls["missed"].truth).group(1))
    late = int(re.search(r"from line (\d+)", pitfalls["late"].truth).group(1))
    assert missed < 100 < late and late - missed == 100


def test_method_keys_in_stability_are_not_names(tunnel):
    """The tunnelling groups are made of the methods' own keys."""
    keys = {m.key for m in BUILTIN}
    for r in tunnel:
        if r.method != tunnelling.SWEPT:
            assert set(r.method.split("/")) <= keys
    assert method("tile").averaged and "tile" not in {k for r in tunnel for k in r.method.split("/")}
