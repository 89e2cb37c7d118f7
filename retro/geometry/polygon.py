"""Polygons: validation, winding, convexity, rotation, and convex decomposition of concave polygons.

A polygon is a sequence of (x, y) vertices in either winding, *not* closed (do not repeat the first
vertex at the end). Angles are in radians, counter-clockwise positive in a y-up frame (on a y-down
screen the same angle turns clockwise).

Degenerate input is refused with an InputError naming the problem: fewer than 3 vertices, NaN or
infinite coordinates, repeated vertices, three consecutive collinear vertices (drop the middle one,
`simplify_polygon` does it for you), zero area, self-intersection, and non-convex input to a
routine that needs a convex polygon.

Concave polygons are split into convex pieces by ear clipping (triangles) followed by merging
adjacent pieces across a diagonal whenever the union stays strictly convex (Hertel & Mehlhorn's
greedy merge: at most 4x the optimal number of pieces).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from retro.errors import InputError
from retro.geometry.vectors import Number, PointLike, as_number, as_point, as_points

Polygon = list[tuple[float, float]]

# Relative tolerance for "collinear" / "zero area" on float input: a cross product smaller than
# this fraction of |e1| * |e2| counts as zero. Integer input below 2**26 is computed exactly.
COLLINEAR_TOLERANCE = 1e-12


def signed_area(points: Sequence[PointLike] | np.ndarray) -> float:
    """Shoelace area: > 0 for counter-clockwise (y up), < 0 for clockwise."""
    p = as_points(points)
    x, y = p[:, 0], p[:, 1]
    return float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)) / 2


def is_ccw(points: Sequence[PointLike] | np.ndarray) -> bool:
    """True when the vertices run counter-clockwise in a y-up frame (positive signed area)."""
    return signed_area(points) > 0


def _turn(p: Sequence[float], q: Sequence[float], r: Sequence[float]) -> float:
    """Cross product of (q - p) and (r - q): > 0 for a left (counter-clockwise) turn at q."""
    return (q[0] - p[0]) * (r[1] - q[1]) - (q[1] - p[1]) * (r[0] - q[0])


def _is_straight(p: Sequence[float], q: Sequence[float], r: Sequence[float]) -> bool:
    turn = _turn(p, q, r)
    scale = math.hypot(q[0] - p[0], q[1] - p[1]) * math.hypot(r[0] - q[0], r[1] - q[1])
    return abs(turn) <= COLLINEAR_TOLERANCE * scale


def _segments_intersect(p1, p2, q1, q2) -> bool:
    """Closed segments p1p2 and q1q2 share at least one point."""
    d1, d2 = _turn(q1, q2, p1), _turn(q1, q2, p2)
    d3, d4 = _turn(p1, p2, q1), _turn(p1, p2, q2)
    if ((d1 > 0 > d2) or (d1 < 0 < d2)) and ((d3 > 0 > d4) or (d3 < 0 < d4)):
        return True

    def on_segment(a, b, c) -> bool:  # c collinear with ab: is it within the box of ab?
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])

    return ((d1 == 0 and on_segment(q1, q2, p1)) or (d2 == 0 and on_segment(q1, q2, p2))
            or (d3 == 0 and on_segment(p1, p2, q1)) or (d4 == 0 and on_segment(p1, p2, q2)))


def _basic_checks(points: object, name: str) -> tuple[Polygon, bool]:
    """At least 3 finite, distinct vertices, no collinear triple, non-zero area.
    Returns the vertices counter-clockwise and whether the input order was reversed to get there."""
    if hasattr(points, "__len__") and len(points) < 3:  # type: ignore[arg-type]
        raise InputError(f"{name}: a polygon needs at least 3 vertices, got {len(points)}")  # type: ignore[arg-type]
    array = as_points(points, name)
    n = len(array)
    if n < 3:
        raise InputError(f"{name}: a polygon needs at least 3 vertices, got {n}")
    pts = [(float(x), float(y)) for x, y in array]
    seen: dict[tuple[float, float], int] = {}
    for i, p in enumerate(pts):
        if p in seen:
            hint = " (do not close the ring by repeating the first vertex)" if i == n - 1 and seen[p] == 0 else ""
            raise InputError(f"{name}: vertex {i} repeats vertex {seen[p]} at {p}{hint}")
        seen[p] = i
    area = signed_area(array)
    span = float(np.ptp(array, axis=0).max())
    if abs(area) <= COLLINEAR_TOLERANCE * span * span:
        raise InputError(f"{name}: zero area (all vertices on one line, or the halves cancel)")
    for i in range(n):
        if _is_straight(pts[i - 1], pts[i], pts[(i + 1) % n]):
            raise InputError(f"{name}: vertices {(i - 1) % n}, {i}, {(i + 1) % n} are collinear; "
                             f"remove vertex {i} (simplify_polygon does this)")
    return (pts, False) if area > 0 else (pts[::-1], True)


def _user_index(k: int, n: int, reversed_: bool) -> int:
    """Index k of the counter-clockwise list, in the caller's own vertex numbering."""
    return n - 1 - k if reversed_ else k


def simple_polygon(points: object, name: str = "polygon") -> Polygon:
    """Validate a simple (possibly concave) polygon; return its vertices counter-clockwise."""
    pts, reversed_ = _basic_checks(points, name)
    n = len(pts)
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # adjacent through the wrap-around
            if _segments_intersect(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n]):
                e1 = sorted(_user_index(k % n, n, reversed_) for k in (i, i + 1))
                e2 = sorted(_user_index(k % n, n, reversed_) for k in (j, j + 1))
                raise InputError(f"{name}: self-intersecting (edges {e1[0]}-{e1[1]} and {e2[0]}-{e2[1]} cross)")
    return pts


def is_convex(points: object) -> bool:
    """True when the (valid, simple) polygon turns the same way at every vertex."""
    pts = simple_polygon(points)
    n = len(pts)
    return all(_turn(pts[i - 1], pts[i], pts[(i + 1) % n]) > 0 for i in range(n))


def convex_polygon(points: object, name: str = "polygon") -> Polygon:
    """Validate a strictly convex polygon; return its vertices counter-clockwise (y up)."""
    pts, reversed_ = _basic_checks(points, name)
    n = len(pts)
    for i in range(n):
        if _turn(pts[i - 1], pts[i], pts[(i + 1) % n]) < 0:
            raise InputError(f"{name}: not convex (reflex angle at vertex {_user_index(i, n, reversed_)}); "
                             "use polygons_overlap() or convex_decompose() for concave polygons")
    # Same turn everywhere is not enough: a pentagram turns left at every vertex but winds twice.
    winding = sum(math.atan2(_turn(pts[i - 1], pts[i], pts[(i + 1) % n]),
                             (pts[i][0] - pts[i - 1][0]) * (pts[(i + 1) % n][0] - pts[i][0])
                             + (pts[i][1] - pts[i - 1][1]) * (pts[(i + 1) % n][1] - pts[i][1]))
                  for i in range(n)) / (2 * math.pi)
    if round(winding) != 1:
        raise InputError(f"{name}: self-intersecting (the outline winds {round(winding)} times)")
    return pts


def simplify_polygon(points: object, name: str = "polygon") -> Polygon:
    """Drop repeated vertices (including a closing copy of the first) and the middle vertex of every
    collinear triple. Keeps the input winding. Raises InputError if fewer than 3 vertices remain."""
    pts = [(float(x), float(y)) for x, y in as_points(points, name)]
    changed = True
    while changed and len(pts) >= 3:
        changed = False
        for i in range(len(pts)):
            prev, cur, nxt = pts[i - 1], pts[i], pts[(i + 1) % len(pts)]
            if cur == prev or _is_straight(prev, cur, nxt) or cur == nxt:
                del pts[i]
                changed = True
                break
    if len(pts) < 3:
        raise InputError(f"{name}: fewer than 3 vertices left after removing repeated and collinear ones")
    return pts


def polygon_centroid(points: object) -> tuple[float, float]:
    """Area centroid of a polygon (either winding)."""
    pts = as_points(points)
    x, y = pts[:, 0], pts[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    c = x * y1 - x1 * y
    area = c.sum() / 2
    if area == 0:
        raise InputError("polygon: zero area, no centroid")
    return float(((x + x1) * c).sum() / (6 * area)), float(((y + y1) * c).sum() / (6 * area))


def rotate_point(point: PointLike, angle: float, about: PointLike = (0.0, 0.0)) -> tuple[float, float]:
    """Rotate a point by `angle` radians counter-clockwise (y up) about `about`."""
    px, py = as_point(point)
    ox, oy = as_point(about, "about")
    a = as_number(angle, "angle")
    c, s = math.cos(a), math.sin(a)
    dx, dy = px - ox, py - oy
    return ox + c * dx - s * dy, oy + s * dx + c * dy


def rotate_polygon(points: object, angle: float, about: PointLike | None = None) -> Polygon:
    """Rotate every vertex by `angle` radians about `about` (default: the polygon's centroid)."""
    pts = as_points(points)
    centre = polygon_centroid(pts) if about is None else as_point(about, "about")
    return [rotate_point(p, angle, centre) for p in pts]


def translate_polygon(points: object, offset: PointLike) -> Polygon:
    dx, dy = as_point(offset, "offset")
    return [(float(x) + dx, float(y) + dy) for x, y in as_points(points)]


def regular_polygon(sides: int, radius: Number, center: PointLike = (0.0, 0.0), rotation: float = 0.0) -> Polygon:
    """Counter-clockwise regular polygon; vertex 0 at angle `rotation` from the +x axis."""
    if isinstance(sides, bool) or not isinstance(sides, int) or sides < 3:
        raise InputError(f"sides: need an integer >= 3, got {sides!r}")
    cx, cy = as_point(center, "center")
    r = as_number(radius, "radius")
    if r <= 0:
        raise InputError(f"radius: must be > 0, got {r}")
    return [(cx + r * math.cos(rotation + 2 * math.pi * k / sides), cy + r * math.sin(rotation + 2 * math.pi * k / sides))
            for k in range(sides)]


# --- decomposition ---------------------------------------------------------------------------

def _point_in_closed_triangle(p, a, b, c) -> bool:
    return _turn(a, b, p) >= 0 and _turn(b, c, p) >= 0 and _turn(c, a, p) >= 0


def triangulate(points: object, name: str = "polygon") -> list[tuple[int, int, int]]:
    """Ear clipping: counter-clockwise index triples into the counter-clockwise vertex list that
    `simple_polygon(points)` returns. An ear is a convex vertex whose triangle contains no other
    remaining vertex (boundary included), so its diagonal lies strictly inside the polygon."""
    pts = simple_polygon(points, name)
    remaining = list(range(len(pts)))
    triangles: list[tuple[int, int, int]] = []
    while len(remaining) > 3:
        m = len(remaining)
        for k in range(m):
            i, j, l = remaining[k - 1], remaining[k], remaining[(k + 1) % m]
            a, b, c = pts[i], pts[j], pts[l]
            if _turn(a, b, c) <= 0:
                continue
            if any(_point_in_closed_triangle(pts[v], a, b, c) for v in remaining if v not in (i, j, l)):
                continue
            triangles.append((i, j, l))
            del remaining[k]
            break
        else:  # cannot happen with exact arithmetic (two-ears theorem); floats near degeneracy can
            raise InputError(f"{name}: cannot triangulate (nearly degenerate vertices?)")
    i, j, l = remaining
    if _turn(pts[i], pts[j], pts[l]) > 0:
        triangles.append((i, j, l))
    return triangles


def convex_decompose(points: object, name: str = "polygon") -> list[Polygon]:
    """Split a simple polygon into strictly convex counter-clockwise pieces whose union is the
    polygon. A convex input comes back as one piece."""
    pts = simple_polygon(points, name)
    pieces: dict[int, list[int]] = {k: list(t) for k, t in enumerate(triangulate(pts, name))}
    owner: dict[tuple[int, int], int] = {}
    for k, piece in pieces.items():
        for e in range(len(piece)):
            owner[(piece[e], piece[(e + 1) % len(piece)])] = k
    merged_something = True
    while merged_something:
        merged_something = False
        for (u, v), p in list(owner.items()):
            q = owner.get((v, u))
            if q is None or p == q or p not in pieces or q not in pieces:
                continue
            ring_p, ring_q = pieces[p], pieces[q]
            sp = ring_p.index(v)
            rot_p = ring_p[sp:] + ring_p[:sp]          # v ... u
            sq = ring_q.index(u)
            rot_q = ring_q[sq:] + ring_q[:sq]          # u ... v
            merged = rot_p + rot_q[1:-1]
            n = len(merged)
            if all(_turn(pts[merged[i - 1]], pts[merged[i]], pts[merged[(i + 1) % n]]) > 0 for i in range(n)):
                pieces[p] = merged
                del pieces[q]
                del owner[(u, v)], owner[(v, u)]
                for e in range(n):
                    owner[(merged[e], merged[(e + 1) % n])] = p
                merged_something = True
    return [[pts[i] for i in piece] for piece in pieces.values()]


def convex_hull(points: Sequence[PointLike] | np.ndarray) -> list[tuple]:
    """Convex hull of a set of points by Andrew's monotone chain: counter-clockwise (y up), without
    collinear vertices. Fewer than three distinct points come back as they are (sorted).
    """
    pts = sorted(set(map(tuple, np.asarray(points).tolist())))
    if len(pts) < 3:
        return [tuple(p) for p in pts]

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]
