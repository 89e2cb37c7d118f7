"""Dynamic AABB tree: a binary tree of boxes, each internal node bounding its two children, kept
balanced by rotations, with incremental insert / remove / move.

Leaves store a "fat" box (the object's box grown by `margin` on every side). Moving an object whose
new box still fits inside its fat box costs nothing; only an object that leaves it is removed and
reinserted. Queries prune with the fat boxes but decide with the exact (tight) boxes, so the
results equal brute force exactly.

Insertion walks down from the root choosing the child whose bounding box grows least (perimeter
cost, the 2-D analogue of the surface area heuristic) and stops where making a new sibling is
cheaper; rotations on the way back up keep the heights of siblings within one of each other.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Iterator, Sequence

from retro.errors import InputError
from retro.geometry.aabb import as_box
from retro.geometry.broadphase.boxes import ALL_LAYERS, BoxSet, PairResult
from retro.geometry.rays import slab_interval
from retro.geometry.vectors import PointLike, as_nonzero_vector, as_number, as_point


class _Node:
    __slots__ = ("x0", "y0", "x1", "y1", "parent", "left", "right", "height", "key", "tight", "layer", "mask")

    def __init__(self) -> None:
        self.parent: _Node | None = None
        self.left: _Node | None = None
        self.right: _Node | None = None
        self.height = 0
        self.key: Hashable = None
        self.tight: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
        self.layer = 1
        self.mask = ALL_LAYERS

    def set_box(self, x0: float, y0: float, x1: float, y1: float) -> None:
        self.x0, self.y0, self.x1, self.y1 = x0, y0, x1, y1

    def fit(self) -> None:
        """Bound the two children and update the height."""
        a, b = self.left, self.right
        self.x0, self.y0 = min(a.x0, b.x0), min(a.y0, b.y0)  # type: ignore[union-attr]
        self.x1, self.y1 = max(a.x1, b.x1), max(a.y1, b.y1)  # type: ignore[union-attr]
        self.height = 1 + max(a.height, b.height)  # type: ignore[union-attr]

    @property
    def is_leaf(self) -> bool:
        return self.left is None


def _perimeter(x0: float, y0: float, x1: float, y1: float) -> float:
    return 2 * ((x1 - x0) + (y1 - y0))


def _union_perimeter(a: _Node, b: _Node) -> float:
    return _perimeter(min(a.x0, b.x0), min(a.y0, b.y0), max(a.x1, b.x1), max(a.y1, b.y1))


def _leaves_meet(a: _Node, b: _Node) -> bool:
    """Two leaves are a pair: their tight boxes overlap and each one's layer is in the other's mask."""
    ax0, ay0, ax1, ay1 = a.tight
    bx0, by0, bx1, by1 = b.tight
    return bool(ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1 and a.layer & b.mask and b.layer & a.mask)


class AABBTree:
    """Incremental broad phase. Keys are any hashable, sortable ids you choose (e.g. ints)."""

    def __init__(self, margin: float = 0.0, predict: float = 4.0) -> None:
        """`margin`: how far a leaf's fat box extends beyond the object's box on every side.
        `predict`: when a moved object is reinserted, its fat box is also stretched by this many
        times its last displacement in the direction it moved (objects tend to keep moving)."""
        m = as_number(margin, "margin")
        k = as_number(predict, "predict")
        if m < 0 or k < 0:
            raise InputError(f"margin and predict: must be >= 0, got {m} and {k}")
        self.margin = float(m)
        self.predict = float(k)
        self._root: _Node | None = None
        self._leaves: dict[Hashable, _Node] = {}

    # --- maintenance -------------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self._leaves)

    def __contains__(self, key: object) -> bool:
        return key in self._leaves

    @property
    def height(self) -> int:
        return self._root.height if self._root else 0

    def insert(self, key: Hashable, box_min: PointLike, box_max: PointLike,
               layer: int = 1, mask: int = ALL_LAYERS) -> None:
        """Add an object with its box and collision layers (see broadphase.boxes)."""
        if key in self._leaves:
            raise InputError(f"key {key!r}: already in the tree")
        (x0, y0), (x1, y1) = as_box(box_min, box_max)
        leaf = _Node()
        leaf.key, leaf.layer, leaf.mask = key, int(layer), int(mask)
        leaf.tight = (float(x0), float(y0), float(x1), float(y1))
        m = self.margin
        leaf.set_box(x0 - m, y0 - m, x1 + m, y1 + m)
        self._leaves[key] = leaf
        self._insert_leaf(leaf)

    def remove(self, key: Hashable) -> None:
        leaf = self._leaf(key)
        self._remove_leaf(leaf)
        del self._leaves[key]

    def move(self, key: Hashable, box_min: PointLike, box_max: PointLike) -> bool:
        """Give an object its new box. Returns True when it left its fat box and was reinserted."""
        (x0, y0), (x1, y1) = as_box(box_min, box_max)
        return self._move(self._leaf(key), float(x0), float(y0), float(x1), float(y1))

    def move_many(self, keys: Sequence[Hashable], mins: object, maxs: object) -> int:
        """move() for many objects at once, boxes as (N, 2) arrays checked in one go (one frame of
        a game loop). Returns how many were reinserted."""
        boxes = BoxSet.from_arrays(mins, maxs)
        if len(keys) != len(boxes):
            raise InputError(f"move_many: {len(keys)} keys but {len(boxes)} boxes")
        x0, y0, x1, y1, _, _ = boxes.columns()
        leaves = [self._leaf(key) for key in keys]
        return sum(self._move(leaf, x0[i], y0[i], x1[i], y1[i]) for i, leaf in enumerate(leaves))

    def _move(self, leaf: _Node, x0: float, y0: float, x1: float, y1: float) -> bool:
        dx, dy = (x0 - leaf.tight[0]) * self.predict, (y0 - leaf.tight[1]) * self.predict
        leaf.tight = (x0, y0, x1, y1)
        if leaf.x0 <= x0 and leaf.y0 <= y0 and x1 <= leaf.x1 and y1 <= leaf.y1:
            return False
        self._remove_leaf(leaf)
        m = self.margin
        leaf.set_box(x0 - m + min(dx, 0.0), y0 - m + min(dy, 0.0), x1 + m + max(dx, 0.0), y1 + m + max(dy, 0.0))
        leaf.parent = None
        self._insert_leaf(leaf)
        return True

    def box(self, key: Hashable) -> tuple[tuple[float, float], tuple[float, float]]:
        x0, y0, x1, y1 = self._leaf(key).tight
        return (x0, y0), (x1, y1)

    def _leaf(self, key: Hashable) -> _Node:
        try:
            return self._leaves[key]
        except (KeyError, TypeError):
            raise InputError(f"key {key!r}: not in the tree") from None

    def _insert_leaf(self, leaf: _Node) -> None:
        if self._root is None:
            self._root = leaf
            return
        node = self._root
        while not node.is_leaf:
            area = _perimeter(node.x0, node.y0, node.x1, node.y1)
            combined = _union_perimeter(node, leaf)
            cost_here = 2 * combined  # new parent of this node and the leaf
            inherited = 2 * (combined - area)  # growth pushed onto every ancestor below here
            costs = []
            for child in (node.left, node.right):
                grown = _union_perimeter(child, leaf)  # type: ignore[arg-type]
                if not child.is_leaf:  # type: ignore[union-attr]
                    grown -= _perimeter(child.x0, child.y0, child.x1, child.y1)  # type: ignore[union-attr]
                costs.append(grown + inherited)
            if cost_here < costs[0] and cost_here < costs[1]:
                break
            node = node.left if costs[0] <= costs[1] else node.right  # type: ignore[assignment]
        sibling = node
        parent = _Node()
        old_parent = sibling.parent
        parent.parent = old_parent
        parent.left, parent.right = sibling, leaf
        sibling.parent = leaf.parent = parent
        parent.fit()
        if old_parent is None:
            self._root = parent
        elif old_parent.left is sibling:
            old_parent.left = parent
        else:
            old_parent.right = parent
        self._refit_from(parent)

    def _remove_leaf(self, leaf: _Node) -> None:
        if leaf is self._root:
            self._root = None
            return
        parent = leaf.parent
        grand = parent.parent  # type: ignore[union-attr]
        sibling = parent.right if parent.left is leaf else parent.left  # type: ignore[union-attr]
        sibling.parent = grand  # type: ignore[union-attr]
        if grand is None:
            self._root = sibling
        else:
            if grand.left is parent:
                grand.left = sibling
            else:
                grand.right = sibling
            self._refit_from(grand)
        leaf.parent = None

    def _refit_from(self, node: _Node | None) -> None:
        while node is not None:
            node = self._balance(node)
            node.fit()
            node = node.parent

    def _replace_child(self, old: _Node, new: _Node) -> None:
        parent = old.parent
        new.parent = parent
        if parent is None:
            self._root = new
        elif parent.left is old:
            parent.left = new
        else:
            parent.right = new

    def _balance(self, a: _Node) -> _Node:
        """If one child of `a` is more than one level taller, rotate it up; return the subtree root."""
        if a.is_leaf or a.height < 2:
            return a
        b, c = a.left, a.right
        balance = c.height - b.height  # type: ignore[union-attr]
        if balance > 1:
            tall, low = (c.left, c.right) if c.left.height > c.right.height else (c.right, c.left)  # type: ignore[union-attr]
            self._replace_child(a, c)  # type: ignore[arg-type]
            c.left, c.right = a, tall  # type: ignore[union-attr]
            a.parent = c
            a.right, low.parent = low, a  # type: ignore[union-attr]
            a.fit()
            c.fit()  # type: ignore[union-attr]
            return c  # type: ignore[return-value]
        if balance < -1:
            tall, low = (b.left, b.right) if b.left.height > b.right.height else (b.right, b.left)  # type: ignore[union-attr]
            self._replace_child(a, b)  # type: ignore[arg-type]
            b.left, b.right = a, tall  # type: ignore[union-attr]
            a.parent = b
            a.left, low.parent = low, a  # type: ignore[union-attr]
            a.fit()
            b.fit()  # type: ignore[union-attr]
            return b  # type: ignore[return-value]
        return a

    # --- queries ---------------------------------------------------------------------------

    def query(self, box_min: PointLike, box_max: PointLike) -> list[Hashable]:
        """Keys whose (tight) boxes overlap the given box, strict convention, sorted. No layers."""
        (qx0, qy0), (qx1, qy1) = as_box(box_min, box_max)
        found = []
        stack = [self._root] if self._root else []
        while stack:
            node = stack.pop()
            if node.x1 < qx0 or qx1 < node.x0 or node.y1 < qy0 or qy1 < node.y0:
                continue
            if node.is_leaf:
                x0, y0, x1, y1 = node.tight
                if x0 < qx1 and qx0 < x1 and y0 < qy1 and qy0 < y1:
                    found.append(node.key)
            else:
                stack.append(node.left)
                stack.append(node.right)
        return sorted(found)  # type: ignore[type-var]

    def pairs(self) -> PairResult:
        """All candidate pairs (key_i < key_j, sorted) with overlapping tight boxes and matching
        layers, by descending the tree against itself: every pair of leaves is examined at most
        once, at their lowest common ancestor, and subtrees whose fat boxes are apart are skipped."""
        pairs = []
        tests = 0
        if self._root is None:
            return PairResult(pairs, 0)
        selfs = [self._root]
        crosses: list[tuple[_Node, _Node]] = []
        while selfs or crosses:
            if selfs:
                node = selfs.pop()
                if not node.is_leaf:
                    selfs.append(node.left)  # type: ignore[arg-type]
                    selfs.append(node.right)  # type: ignore[arg-type]
                    crosses.append((node.left, node.right))  # type: ignore[arg-type]
                continue
            a, b = crosses.pop()
            if a.x1 < b.x0 or b.x1 < a.x0 or a.y1 < b.y0 or b.y1 < a.y0:
                continue
            if a.is_leaf and b.is_leaf:
                tests += 1
                if _leaves_meet(a, b):
                    pairs.append((a.key, b.key) if a.key < b.key else (b.key, a.key))  # type: ignore[operator]
            elif b.is_leaf or (not a.is_leaf and a.height >= b.height):
                crosses.append((a.left, b))  # type: ignore[arg-type]
                crosses.append((a.right, b))  # type: ignore[arg-type]
            else:
                crosses.append((a, b.left))  # type: ignore[arg-type]
                crosses.append((a, b.right))  # type: ignore[arg-type]
        pairs.sort()
        return PairResult(pairs, tests)

    def raycast(self, origin: PointLike, direction: PointLike,
                hit_time: Callable[[Hashable], float | None], max_t: float = math.inf) -> tuple[float, Hashable, int] | None:
        """First hit along a ray: visits only leaves whose fat box the ray reaches before the best
        hit so far, calling `hit_time(key)` (exact shape test, t >= 0 or None) for each. Returns
        (t, key, shapes_tested) for the smallest t <= max_t (ties: smallest key), or None."""
        o = as_point(origin, "origin")
        d = as_nonzero_vector(direction, "direction")
        best: tuple[float, Hashable] | None = None
        limit = max_t
        tested = 0
        stack = [self._root] if self._root else []
        while stack:
            node = stack.pop()
            span = slab_interval(o, d, (node.x0, node.y0), (node.x1, node.y1), closed=True)
            if span is None or span[1] < 0 or span[0] > limit:
                continue
            if node.is_leaf:
                tested += 1
                t = hit_time(node.key)
                if t is not None and t <= limit and (best is None or (t, node.key) < best):  # type: ignore[operator]
                    best, limit = (t, node.key), t
                continue
            stack.append(node.left)  # type: ignore[arg-type]
            stack.append(node.right)  # type: ignore[arg-type]
        return None if best is None else (best[0], best[1], tested)

    def nodes(self) -> Iterator[tuple[tuple[float, float, float, float], int, bool]]:
        """((x0, y0, x1, y1), depth, is_leaf) for every node (fat boxes), for pictures."""
        stack = [(self._root, 0)] if self._root else []
        while stack:
            node, depth = stack.pop()
            yield (node.x0, node.y0, node.x1, node.y1), depth, node.is_leaf
            if not node.is_leaf:
                stack.append((node.left, depth + 1))
                stack.append((node.right, depth + 1))

    def check(self) -> None:
        """Assert the tree invariants (parents, bounds, heights, balance); for tests."""
        count = 0
        stack = [self._root] if self._root else []
        while stack:
            node = stack.pop()
            if node.is_leaf:
                count += 1
                x0, y0, x1, y1 = node.tight
                assert node.x0 <= x0 and node.y0 <= y0 and x1 <= node.x1 and y1 <= node.y1
                assert node.height == 0
                continue
            for child in (node.left, node.right):
                assert child.parent is node
                assert node.x0 <= child.x0 and node.y0 <= child.y0 and child.x1 <= node.x1 and child.y1 <= node.y1
                stack.append(child)
            assert node.height == 1 + max(node.left.height, node.right.height)
            assert abs(node.left.height - node.right.height) <= 1
        assert count == len(self._leaves)


def aabb_tree_pairs(boxes: BoxSet, margin: float = 0.0) -> PairResult:
    """Build a tree over the boxes (keys 0..N-1) and return its candidate pairs."""
    tree = AABBTree(margin)
    x0, y0, x1, y1, layers, masks = boxes.columns()
    for i in range(len(x0)):
        tree.insert(i, (x0[i], y0[i]), (x1[i], y1[i]), layers[i], masks[i])
    return tree.pairs()
