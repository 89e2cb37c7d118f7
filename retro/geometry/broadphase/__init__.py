"""Broad phases: find the pairs of boxes worth a narrow-phase test without testing all N^2 pairs.

Every method returns exactly the pairs brute force returns (strictly overlapping boxes whose
layers match, i < j, sorted) plus the number of pair tests it performed.
"""

from retro.geometry.broadphase.aabbtree import AABBTree, aabb_tree_pairs
from retro.geometry.broadphase.boxes import ALL_LAYERS, BoxSet, PairResult, layers_match
from retro.geometry.broadphase.brute import brute_force_pairs, brute_force_pairs_numpy
from retro.geometry.broadphase.grid import choose_cell_size, grid_pairs
from retro.geometry.broadphase.quadtree import Quadtree, quadtree_pairs
from retro.geometry.broadphase.sweep import choose_axis, sweep_and_prune_pairs

# name -> function(BoxSet) -> PairResult, brute force first: the reference.
METHODS = {
    "brute force": brute_force_pairs,
    "brute force (numpy)": brute_force_pairs_numpy,
    "grid": grid_pairs,
    "sort and sweep": sweep_and_prune_pairs,
    "quadtree": quadtree_pairs,
    "AABB tree": aabb_tree_pairs,
}

__all__ = [
    "ALL_LAYERS", "AABBTree", "BoxSet", "METHODS", "PairResult", "Quadtree", "aabb_tree_pairs",
    "brute_force_pairs", "brute_force_pairs_numpy", "choose_axis", "choose_cell_size", "grid_pairs",
    "layers_match", "quadtree_pairs", "sweep_and_prune_pairs",
]
