"""`retro advise`: --software, NES scenes (their sprites from OAM and CHR, the sprite-0 hit), --objects N
(choice by cycles per frame)."""

from __future__ import annotations

import sys
from itertools import combinations

import numpy as np
import pytest

from retro.analysis.study.advisor import advice_lines, advise, nes_shapes
from retro.paths import EXAMPLES_DIR, SPRITES_DIR

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

NES_SCENE = str(EXAMPLES_DIR / "nes_sprite0.toml")


@pytest.fixture(scope="module")
def two_sprites(tmp_path_factory):
    scene = tmp_path_factory.mktemp("advise") / "pair.toml"
    scene.write_text(f"""chip = "vic-ii"
video = "pal"
[[sprite]]
index = 0
x = 100
y = 100
file = "{SPRITES_DIR / 'ball.spr'}"
[[sprite]]
index = 3
x = 130
y = 100
file = "{SPRITES_DIR / 'bar.spr'}"
""")
    return str(scene)


def test_software_leaves_the_latch_out(two_sprites):
    """Two sprites: the latch wins (exact, 19 cycles); without hardware the tight box from prepared
    edges does, and the advice says what was left out."""
    plain = advise(two_sprites, 0.9, workers=1)
    assert plain.chosen.key == "latch"
    soft = advise(two_sprites, 0.9, workers=1, software=True)
    assert soft.chosen.key == "tight_edges"
    assert "latch" not in {f.key for f in soft.figures}
    assert any(line.startswith("  note: --software: left out VIC-II latch") for line in advice_lines(soft))


def _coin_mask() -> np.ndarray:
    """Sprite 0 of examples/nes_sprite0.toml: CHR tile 0:4, its non-zero pattern values opaque."""
    doc = tomllib.loads(open(NES_SCENE).read())
    rows = doc["chr"]["tiles"]["0:4"]
    return np.array([[c not in ".0" for c in row] for row in rows])


def test_nes_scene_sprites_from_oam_and_chr():
    from retro.scenes import load_scene

    found = nes_shapes(load_scene(NES_SCENE))
    assert [n for n, _ in found] == [0, 1]  # both OAM entries given are on screen
    for _, shape in found:  # the second entry only changes the palette (attr 1): the same pixels
        assert shape.mask.shape == (8, 8) and np.array_equal(shape.mask, _coin_mask())


def test_nes_advice_software_methods_and_sprite_zero():
    """Two coins: only software methods take part (the latch and the 9-bit sprite edges are the C64's);
    the tight box's accuracy is the share of the 15 x 15 offsets where boxes and pixels agree,
    counted here; the sprite-0 hit of the scene is the one docs/nes.md gives (x 91, line 26)."""
    import independent as ind

    advice = advise(NES_SCENE, 0.99, workers=1)
    keys = {f.key for f in advice.figures}
    assert "latch" not in keys and "sprite_edges" not in keys
    assert advice.chosen.key == "pixel"  # the only exact software method
    coin = _coin_mask()
    offsets = ind.all_offsets(coin, coin)
    assert len(offsets) == 15 * 15 == advice.cases
    truth = ind.pixel_hits(coin, coin, offsets)
    box = ind.bounds(coin)
    tp, fp, tn, fn = ind.counts([float(v) for v in ind.box_hits(box, box, offsets)], truth)
    tight = next(f for f in advice.figures if f.key == "tight")
    assert tight.counts.accuracy == pytest.approx((tp + tn) / len(offsets))
    lines = advice_lines(advice)
    assert any("not on the NES: tight hitbox, 9-bit sprite edges, VIC-II latch $D01E" in line for line in lines)
    assert any("sprite-0 hit" in line and "x 91, line 26" in line for line in lines)
    assert "NES NTSC" in lines[0]


def test_objects_two_and_sixteen():
    """Per frame: with 2 objects the latch serves (19 cycles a frame); with 16 it cannot (more objects
    than sprites) and the cheapest qualifying method by cycles per frame is chosen, its frame the
    smallest of those that qualify."""
    scene = str(EXAMPLES_DIR / "vic_two_balls.toml")
    two = advise(scene, 0.9, workers=1, objects=2)
    assert two.chosen.key == "latch" and two.chosen.frame.frame_cycles == 19
    many = advise(scene, 0.9, workers=1, objects=16)
    latch = next(f for f in many.figures if f.key == "latch")
    assert not latch.qualifies and "more than the VIC-II's 8 sprites" in latch.note
    qualifying = [f for f in many.figures if f.qualifies]
    assert many.chosen.frame.frame_cycles == min(f.frame.frame_cycles for f in qualifying)
    costs = [f.frame.frame_cycles for f in many.figures if f.frame is not None]
    assert costs == sorted(costs)
    for f in many.figures:
        if f.frame is not None and f.frame.phase != "once":
            r = f.frame
            assert r.objects == 16
            assert r.frame_cycles == pytest.approx(r.prepare_cycles + r.broad_cycles + r.candidates * r.test_cycles)
    lines = advice_lines(many)
    assert any(line.startswith("budget: ") for line in lines)


def test_objects_on_the_nes_uses_its_frame():
    advice = advise(NES_SCENE, 0.99, workers=1, objects=8)
    assert advice.budget.label == "NES NTSC" and advice.budget.frame_cycles * 3 == 341 * 262
    share = advice.chosen.frame.frame_cycles / (341 * 262 / 3)
    chosen = next(line for line in advice_lines(advice) if line.startswith("advice:"))
    assert f"{100 * share:.1f}% of a NES NTSC frame" in chosen


def test_cli_software_and_objects(two_sprites):
    import subprocess

    done = subprocess.run([sys.executable, "-m", "retro", "advise", two_sprites, "--accuracy", "0.9", "--software",
                           "--objects", "12", "--quiet", "--jobs", "1"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    advice = next(line for line in done.stdout.splitlines() if line.startswith("advice:"))
    assert "cycles per frame for 12 objects" in advice
    assert not any("VIC-II latch $D01E:" in line for line in done.stdout.splitlines())  # named in the note only


def test_pairs_of_identical_sprites_are_weighted():
    """Five sprites of two kinds: 10 sprite pairs, evaluated as the distinct shape pairs."""
    advice = advise(str(EXAMPLES_DIR / "vic_two_balls.toml"), 0.9, workers=1)
    assert advice.sprite_pairs == len(list(combinations(advice.sprites, 2)))
