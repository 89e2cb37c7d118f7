"""Region quadtree: each box is stored in the smallest node whose square fully contains it; a node
splits into four when it holds more than `capacity` boxes. A box is tested against the other boxes
in its node and in the nodes below it (boxes straddling a split line stay in the parent)."""

from __future__ import annotations

from retro.errors import InputError
from retro.geometry.broadphase.boxes import BoxSet, PairResult


class _Node:
    __slots__ = ("x0", "y0", "x1", "y1", "depth", "items", "children")

    def __init__(self, x0: float, y0: float, x1: float, y1: float, depth: int) -> None:
        self.x0, self.y0, self.x1, self.y1, self.depth = x0, y0, x1, y1, depth
        self.items: list[int] = []
        self.children: list[_Node] | None = None


class Quadtree:
    """A quadtree over a fixed square region; boxes outside it stay in the root (still correct)."""

    def __init__(self, boxes: BoxSet, capacity: int = 8, max_depth: int = 10) -> None:
        if capacity < 1 or max_depth < 0:
            raise InputError("quadtree: capacity must be >= 1 and max_depth >= 0")
        self.capacity, self.max_depth = capacity, max_depth
        self._x0, self._y0, self._x1, self._y1, self._layers, self._masks = boxes.columns()
        if len(boxes):
            lo, hi = boxes.mins.min(axis=0), boxes.maxs.max(axis=0)
            side = max(float((hi - lo).max()), 1e-9)  # a square root node keeps cells square
            self.root = _Node(float(lo[0]), float(lo[1]), float(lo[0]) + side, float(lo[1]) + side, 0)
        else:
            self.root = _Node(0.0, 0.0, 1.0, 1.0, 0)
        for i in range(len(boxes)):
            self._insert(self.root, i)

    def _child_for(self, node: _Node, i: int) -> _Node | None:
        mx, my = (node.x0 + node.x1) / 2, (node.y0 + node.y1) / 2
        if self._x1[i] <= mx:
            col = 0
        elif self._x0[i] >= mx:
            col = 1
        else:
            return None
        if self._y1[i] <= my:
            row = 0
        elif self._y0[i] >= my:
            row = 1
        else:
            return None
        return node.children[row * 2 + col]  # type: ignore[index]

    def _insert(self, node: _Node, i: int) -> None:
        while node.children is not None:
            child = self._child_for(node, i)
            if child is None:
                break
            node = child
        node.items.append(i)
        if node.children is None and len(node.items) > self.capacity and node.depth < self.max_depth:
            self._split(node)

    def _split(self, node: _Node) -> None:
        mx, my = (node.x0 + node.x1) / 2, (node.y0 + node.y1) / 2
        d = node.depth + 1
        node.children = [_Node(node.x0, node.y0, mx, my, d), _Node(mx, node.y0, node.x1, my, d),
                         _Node(node.x0, my, mx, node.y1, d), _Node(mx, my, node.x1, node.y1, d)]
        keep = []
        for i in node.items:
            child = self._child_for(node, i)
            if child is None:
                keep.append(i)
            else:
                self._insert(child, i)
        node.items = keep

    def depth(self) -> int:
        deepest, stack = 0, [self.root]
        while stack:
            node = stack.pop()
            deepest = max(deepest, node.depth)
            stack.extend(node.children or ())
        return deepest

    def nodes(self) -> list[tuple[float, float, float, float]]:
        """(x0, y0, x1, y1) of every node, for pictures."""
        out, stack = [], [self.root]
        while stack:
            node = stack.pop()
            out.append((node.x0, node.y0, node.x1, node.y1))
            stack.extend(node.children or ())
        return out

    def pairs(self) -> PairResult:
        x0, y0, x1, y1, layers, masks = self._x0, self._y0, self._x1, self._y1, self._layers, self._masks
        pairs = []
        tests = 0
        stack: list[tuple[_Node, list[int]]] = [(self.root, [])]
        while stack:
            node, above = stack.pop()
            items = node.items
            for a, i in enumerate(items):
                for j in items[a + 1:] + above:
                    tests += 1
                    if (x0[i] < x1[j] and x0[j] < x1[i] and y0[i] < y1[j] and y0[j] < y1[i]
                            and layers[i] & masks[j] and layers[j] & masks[i]):
                        pairs.append((i, j) if i < j else (j, i))
            if node.children:
                candidates = above + items
                for child in node.children:
                    # Only boxes reaching into the child's square can overlap a box stored below it.
                    near = [j for j in candidates
                            if x0[j] <= child.x1 and child.x0 <= x1[j] and y0[j] <= child.y1 and child.y0 <= y1[j]]
                    stack.append((child, near))
        pairs.sort()
        return PairResult(pairs, tests)


def quadtree_pairs(boxes: BoxSet, capacity: int = 8, max_depth: int = 10) -> PairResult:
    """Build a quadtree over the boxes and return its candidate pairs."""
    return Quadtree(boxes, capacity, max_depth).pairs()
