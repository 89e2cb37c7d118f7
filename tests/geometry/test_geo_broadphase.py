"""Every broad phase returns exactly the pairs brute force returns, layers included."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from retro.geometry import AABBTree, BoxSet, aabb_overlap, layers_match
from retro.geometry.broadphase import (
    METHODS,
    Quadtree,
    grid_pairs,
    sweep_and_prune_pairs,
)

ENEMY, BULLET, PLAYER = 1, 2, 4


def definition_pairs(boxes: BoxSet) -> list[tuple[int, int]]:
    """Straight from the rule: every i < j whose boxes overlap (aabb_overlap) and layers match."""
    out = []
    for i, j in itertools.combinations(range(len(boxes)), 2):
        if aabb_overlap(boxes.mins[i], boxes.maxs[i], boxes.mins[j], boxes.maxs[j]) and layers_match(
                int(boxes.layers[i]), int(boxes.masks[i]), int(boxes.layers[j]), int(boxes.masks[j])):
            out.append((i, j))
    return out


def scene(rng, n, kind):
    if kind == "uniform":
        mins = rng.uniform(0, 100, (n, 2))
    elif kind == "clustered":
        centres = rng.uniform(0, 100, (4, 2))
        mins = centres[rng.integers(0, 4, n)] + rng.normal(0, 4, (n, 2))
    else:  # integer pixels: many boxes touch exactly, which must not count
        mins = rng.integers(0, 30, (n, 2)).astype(float)
    sizes = rng.integers(0, 8, (n, 2)).astype(float) if kind == "pixels" else rng.uniform(0, 9, (n, 2))
    if kind == "uniform":
        sizes[: n // 20] *= 6  # a few large boxes
    return mins, mins + sizes


@pytest.mark.parametrize("kind", ["uniform", "clustered", "pixels"])
@pytest.mark.parametrize("n", [0, 1, 2, 7, 60, 400])
def test_all_methods_equal_brute_force(kind, n):
    rng = np.random.default_rng(n * 31 + len(kind))
    mins, maxs = scene(rng, n, kind)
    layers = rng.choice([ENEMY, BULLET, PLAYER], n)
    masks = np.where(layers == ENEMY, BULLET | PLAYER, np.where(layers == BULLET, ENEMY, ENEMY))
    for with_layers in (False, True):
        boxes = BoxSet.from_arrays(mins, maxs, layers if with_layers else None, masks if with_layers else None)
        expected = definition_pairs(boxes) if n <= 60 else METHODS["brute force"](boxes).pairs
        assert METHODS["brute force"](boxes).pairs == expected
        for name, method in METHODS.items():
            result = method(boxes)
            assert result.pairs == expected, name
            assert result.tests <= max(n * (n - 1) // 2, 0) or name.startswith("brute")


def test_layers_only_enemies_vs_bullets():
    # Three boxes on top of each other: enemy, enemy, bullet. Only enemy-bullet pairs survive.
    boxes = BoxSet.from_arrays([(0, 0)] * 3, [(2, 2)] * 3, [ENEMY, ENEMY, BULLET], [BULLET, BULLET, ENEMY])
    for name, method in METHODS.items():
        assert method(boxes).pairs == [(0, 2), (1, 2)], name


def test_broad_phases_test_fewer_pairs_than_brute_force():
    rng = np.random.default_rng(3)
    mins = rng.uniform(0, 400, (1000, 2))
    boxes = BoxSet.from_arrays(mins, mins + 4)
    brute = METHODS["brute force"](boxes).tests
    for name in ("grid", "sort and sweep", "quadtree", "AABB tree"):
        assert METHODS[name](boxes).tests < brute / 20, name


def test_grid_and_sweep_options():
    rng = np.random.default_rng(4)
    mins = rng.uniform(0, 50, (200, 2))
    boxes = BoxSet.from_arrays(mins, mins + rng.uniform(0, 5, (200, 2)))
    expected = METHODS["brute force"](boxes).pairs
    for cell in (0.5, 3, 100):
        assert grid_pairs(boxes, cell).pairs == expected
    for axis in (0, 1):
        assert sweep_and_prune_pairs(boxes, axis).pairs == expected
    assert Quadtree(boxes, capacity=1, max_depth=3).pairs().pairs == expected


def test_aabb_tree_incremental_moves_match_brute_force():
    rng = np.random.default_rng(5)
    n = 150
    pos = rng.uniform(0, 60, (n, 2))
    size = rng.uniform(0.5, 5, (n, 2))
    layers = rng.choice([ENEMY, BULLET], n)
    masks = np.where(layers == ENEMY, BULLET, ENEMY)
    tree = AABBTree(margin=1.0)
    alive = set(range(n))
    for i in range(n):
        tree.insert(i, pos[i], pos[i] + size[i], int(layers[i]), int(masks[i]))
    reinserted = 0
    for step in range(30):
        vel = rng.normal(0, 0.6, (n, 2))
        for i in sorted(alive):
            pos[i] += vel[i]
            reinserted += tree.move(i, pos[i], pos[i] + size[i])
        if step % 5 == 4:  # churn: remove a few, bring back a few
            for i in rng.choice(sorted(alive), 5, replace=False):
                tree.remove(int(i))
                alive.discard(int(i))
            for i in rng.choice(sorted(set(range(n)) - alive), 3, replace=False):
                tree.insert(int(i), pos[i], pos[i] + size[i], int(layers[i]), int(masks[i]))
                alive.add(int(i))
        tree.check()
        ids = sorted(alive)
        boxes = BoxSet.from_arrays(pos[ids], pos[ids] + size[ids], layers[ids], masks[ids])
        expected = [(ids[a], ids[b]) for a, b in METHODS["brute force"](boxes).pairs]
        assert tree.pairs().pairs == expected
        probe_lo, probe_hi = pos[ids[0]], pos[ids[0]] + 10
        assert tree.query(probe_lo, probe_hi) == [i for i in ids if aabb_overlap(probe_lo, probe_hi, pos[i], pos[i] + size[i])]
    assert 0 < reinserted < 30 * n  # the fat margin saves most reinsertions
    assert tree.height <= 2 * np.log2(n) + 2  # stays balanced


def test_tree_errors():
    from retro.errors import InputError

    tree = AABBTree()
    tree.insert("a", (0, 0), (1, 1))
    with pytest.raises(InputError, match="already in the tree"):
        tree.insert("a", (0, 0), (1, 1))
    with pytest.raises(InputError, match="not in the tree"):
        tree.move("b", (0, 0), (1, 1))
    with pytest.raises(InputError, match="greater than"):
        BoxSet.from_arrays([(0, 0)], [(-1, 1)])
