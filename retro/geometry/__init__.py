"""Reference geometry from the collision literature: pure functions on plain data and numpy arrays.

Conventions shared by every function here (see docs/geometry.md):
- Points are (x, y) pairs; polygons are sequences of vertices in either winding, not closed.
- Only interiors collide: touching boxes, tangent circles and polygons meeting along an edge or at
  a vertex are separated (strict inequalities). Pixel masks have no touching case.
- An MTV (axis, depth) always means: move the first shape by axis * depth to separate it.
- Bad input (NaN, infinity, degenerate polygons, zero-length rays) raises retro.errors.InputError
  naming the argument and the problem.

This package imports nothing from retro.cpu or retro.chips.
"""

from retro.geometry.aabb import (
    aabb_contains_point,
    aabb_from_center,
    aabb_mtv,
    aabb_overlap,
    aabb_overlap_centered,
    aabb_to_center,
)
from retro.geometry.broadphase import (
    ALL_LAYERS,
    AABBTree,
    BoxSet,
    PairResult,
    Quadtree,
    aabb_tree_pairs,
    brute_force_pairs,
    brute_force_pairs_numpy,
    grid_pairs,
    layers_match,
    quadtree_pairs,
    sweep_and_prune_pairs,
)
from retro.geometry.circle import (
    circle_aabb_mtv,
    circle_aabb_overlap,
    circle_mtv,
    circle_overlap,
    closest_point_on_aabb,
    point_in_circle,
)
from retro.geometry.masks import (
    mask_bounds,
    mask_from_rows,
    mask_overlap,
    mask_overlap_area,
    mask_overlap_mask,
)
from retro.geometry.polygon import (
    convex_decompose,
    convex_hull,
    convex_polygon,
    is_ccw,
    is_convex,
    polygon_centroid,
    regular_polygon,
    rotate_point,
    rotate_polygon,
    signed_area,
    simple_polygon,
    simplify_polygon,
    translate_polygon,
    triangulate,
)
from retro.geometry.raycast import Box, Circle, RayHit, RayScene, Segment
from retro.geometry.rays import ray_aabb, ray_circle, ray_segment
from retro.geometry.response import bounce, separate, slide
from retro.geometry.sat import pieces_overlap, polygons_overlap, sat, sat_overlap
from retro.geometry.swept import SweptHit, swept_aabb, swept_aabb_hit, swept_circle

__all__ = [
    "ALL_LAYERS", "AABBTree", "Box", "BoxSet", "Circle", "PairResult", "Quadtree", "RayHit", "RayScene",
    "Segment", "SweptHit", "aabb_contains_point", "aabb_from_center", "aabb_mtv", "aabb_overlap",
    "aabb_overlap_centered", "aabb_to_center", "aabb_tree_pairs", "bounce", "brute_force_pairs",
    "brute_force_pairs_numpy", "circle_aabb_mtv", "circle_aabb_overlap", "circle_mtv", "circle_overlap",
    "closest_point_on_aabb", "convex_decompose", "convex_hull", "convex_polygon", "grid_pairs", "is_ccw", "is_convex",
    "layers_match", "mask_bounds", "mask_from_rows", "mask_overlap", "mask_overlap_area", "mask_overlap_mask",
    "pieces_overlap", "point_in_circle", "polygon_centroid", "polygons_overlap", "quadtree_pairs",
    "ray_aabb", "ray_circle", "ray_segment", "regular_polygon", "rotate_point", "rotate_polygon", "sat",
    "sat_overlap", "separate", "signed_area", "simple_polygon", "simplify_polygon", "slide",
    "swept_aabb", "swept_aabb_hit", "swept_circle", "sweep_and_prune_pairs", "translate_polygon",
    "triangulate",
]
