"""Random shapes for the geometry tests (seeded; shapely supplies the convex hulls)."""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import MultiPoint, Polygon

from retro.errors import InputError
from retro.geometry import simple_polygon


def random_convex(rng: np.random.Generator, lo: int = 0, hi: int = 20, integer: bool = True) -> list[tuple[float, float]]:
    """Convex hull of 3-9 random points; returned in a random winding. Retries until valid."""
    while True:
        k = int(rng.integers(3, 10))
        pts = rng.integers(lo, hi + 1, size=(k, 2)) if integer else rng.uniform(lo, hi, size=(k, 2))
        hull = MultiPoint([tuple(map(float, p)) for p in pts]).convex_hull
        if hull.geom_type != "Polygon" or hull.area <= 0:
            continue
        ring = list(hull.exterior.coords)[:-1]
        try:
            simple_polygon(ring)
        except InputError:
            continue  # shapely may keep a collinear vertex; just draw again
        return ring if rng.random() < 0.5 else ring[::-1]


def random_star(rng: np.random.Generator, centre: tuple[float, float], integer: bool = True) -> list[tuple[float, float]]:
    """A star-shaped (usually concave) simple polygon of 5-10 vertices around centre."""
    while True:
        k = int(rng.integers(5, 11))
        angles = np.sort(rng.uniform(0, 2 * math.pi, k))
        radii = rng.uniform(2, 10, k)
        pts = np.column_stack([centre[0] + radii * np.cos(angles), centre[1] + radii * np.sin(angles)])
        if integer:
            pts = np.round(pts)
        ring = [tuple(map(float, p)) for p in pts]
        try:
            simple_polygon(ring)
        except InputError:
            continue
        if not Polygon(ring).is_valid:
            continue
        return ring if rng.random() < 0.5 else ring[::-1]


def interiors_intersect(a, b) -> bool:
    """DE-9IM: the interiors of a and b share a point (shapely's exact predicate)."""
    return bool(shapely.relate_pattern(Polygon(a), Polygon(b), "T********"))
