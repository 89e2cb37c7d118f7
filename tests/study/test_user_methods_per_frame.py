"""A user's method in the cost per frame: its X extent (a broad phase along X must keep its hits), its
preparation scope (`prepare_per`), and the errors of that key."""

from __future__ import annotations

from itertools import combinations_with_replacement
from pathlib import Path

import numpy as np
import pytest

from retro.analysis.study import per_frame as pf
from retro.analysis.study.corpus import make_pair
from retro.analysis.study.methods.user import load_method_file
from retro.cli import main

EDGES_INPUTS = """
[inputs]
a_left = "a_x"
a_top = "a_y"
a_right1 = "a_right1"
a_bottom1 = "a_bottom1"
b_left = "b_x"
b_right = "b_right"
b_top = "b_y"
b_bottom = "b_bottom"
"""


def write(tmp_path: Path, text: str, name: str = "m.toml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("hitbox", [
    'shape = "box"\ntouching = true\n', 'shape = "box"\ninset = [2, 0, -3, 1]\n', 'shape = "circle"\n',
    'shape = "circle"\ntouching = true\ninset = 1\n', 'shape = "mask"\n', 'shape = "box"\nfit = "full"\n',
])
def test_user_extents_keep_every_hit(tmp_path, hitbox, sprite_shapes, hand_shapes):
    """For every case the user's rule calls a hit the two X intervals meet, touching boxes included."""
    m = load_method_file(write(tmp_path, "[hitbox]\n" + hitbox))
    for a, b in combinations_with_replacement(sprite_shapes + hand_shapes, 2):
        pair = make_pair(a, b)
        (alo, ahi), (blo, bhi) = m.x_extent(a), m.x_extent(b)
        meet = np.maximum(alo, blo + pair.dx) < np.minimum(ahi, bhi + pair.dx)
        assert not ((m.verdict(pair) > 0) & ~meet).any(), (hitbox, pair.name)


def test_user_touching_box_extent_by_hand(tmp_path, hand_shapes):
    """The 4x4 block at columns 5-8: its box is [5, 9); touching boxes collide, so one more column."""
    block = hand_shapes[0]
    strict = load_method_file(write(tmp_path, '[hitbox]\nshape = "box"\n', "s.toml"))
    touching = load_method_file(write(tmp_path, '[hitbox]\nshape = "box"\ntouching = true\n', "t.toml"))
    assert strict.x_extent(block) == (5, 9) and touching.x_extent(block) == (5, 10)


def test_prepare_per_kind_pair(tmp_path):
    text = ('routine = "aabb_edges"\nprepare = "aabb_edges_prepare"\nprepare_per = "kind_pair"\n'
            '[hitbox]\nshape = "box"\n' + EDGES_INPUTS)
    m = load_method_file(write(tmp_path, text))
    assert m.prepare_per == "kind_pair"
    assert [pf.prepare_calls(m, n, 3) for n in (1, 2, 3, 10)] == [1, 3, 6, 6]  # K(K+1)/2, K = min(n, 3)
    default = load_method_file(write(tmp_path, text.replace('prepare_per = "kind_pair"\n', ""), "d.toml"))
    assert [pf.prepare_calls(default, n, 3) for n in (1, 2, 3, 10)] == [1, 2, 3, 10]


@pytest.mark.parametrize("text,field", [
    ('routine = "aabb_edges"\nprepare = "aabb_edges_prepare"\nprepare_per = "frame"\n[hitbox]\nshape = "box"\n'
     + EDGES_INPUTS, "prepare_per"),
    ('routine = "aabb_edges"\nprepare_per = "object"\n[hitbox]\nshape = "box"\n' + EDGES_INPUTS, "prepare_per"),
])
def test_prepare_per_errors_are_one_line(tmp_path, capsys, text, field):
    path = write(tmp_path, text)
    assert main(["chart", "--reduced", "--method", path, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and f"{path}: {field}:" in err
