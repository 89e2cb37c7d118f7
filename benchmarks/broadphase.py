"""Broad phase benchmark: pairs tested and time per frame against N, every method in one run.

    python benchmarks/broadphase.py [--sizes 10,30,...] [--frames 3] [--brute-cap 10000] [--plot PATH]

Scenes keep the density constant (the world grows with N), so the number of true overlaps grows
linearly and any super-linear growth is the method's own. "uniform": boxes spread evenly;
"clustered": the same boxes gathered into 8 Gaussian clusters (a crowded scene).
Each frame every object moves a little; the grid, sort-and-sweep, quadtree and brute force rebuild
from scratch each frame, the AABB tree is built once and updated with move() (its build time is
reported separately). Every method's pairs are checked against brute force in the same run.
Ratios are against brute force (plain Python, the same style as the broad phases) measured in
this run; the numpy brute force shows how much is interpreter overhead rather than algorithm.
"""

from __future__ import annotations

import argparse
import io
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from retro.fileio import write_atomic
from retro.geometry.broadphase import (
    AABBTree,
    BoxSet,
    brute_force_pairs,
    brute_force_pairs_numpy,
    grid_pairs,
    quadtree_pairs,
    sweep_and_prune_pairs,
)

REBUILT = {
    "brute force": brute_force_pairs,
    "brute force (numpy)": brute_force_pairs_numpy,
    "grid": grid_pairs,
    "sort and sweep": sweep_and_prune_pairs,
    "quadtree": quadtree_pairs,
}
TREE = "AABB tree"
METHOD_ORDER = list(REBUILT) + [TREE]
DENSITY_SIDE = 20.0   # world side per sqrt(object): constant density
BOX_SIZE = (2.0, 8.0)
SPEED = 0.5           # per-frame displacement scale
TREE_MARGIN = 1.0


def make_scene(n: int, kind: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    side = DENSITY_SIDE * max(np.sqrt(n), 1.0)
    if kind == "uniform":
        pos = rng.uniform(0, side, (n, 2))
    else:
        centres = rng.uniform(0.1 * side, 0.9 * side, (8, 2))
        pos = centres[rng.integers(0, 8, n)] + rng.normal(0, side / 12, (n, 2))
    size = rng.uniform(*BOX_SIZE, (n, 2))
    vel = rng.normal(0, SPEED, (n, 2))
    return pos, size, vel


def run_case(n: int, kind: str, frames: int, brute_cap: int, seed: int) -> dict[str, dict[str, float]]:
    rng = np.random.default_rng(seed)
    pos, size, vel = make_scene(n, kind, rng)
    results: dict[str, dict[str, list[float]]] = {m: {"time": [], "tests": [], "pairs": []} for m in METHOD_ORDER}
    t0 = time.perf_counter()
    tree = AABBTree(margin=TREE_MARGIN)
    for i in range(n):
        tree.insert(i, pos[i], pos[i] + size[i])
    tree_build = time.perf_counter() - t0
    keys = list(range(n))
    warm = BoxSet.from_arrays(pos, pos + size)
    for method in REBUILT.values():  # first calls pay for imports and caches: keep them out of the timing
        if method is not brute_force_pairs or n <= brute_cap:
            method(warm)
    for _ in range(frames):
        pos += vel
        boxes = BoxSet.from_arrays(pos, pos + size)
        reference = None
        for name, method in REBUILT.items():
            if name == "brute force" and n > brute_cap:
                continue
            start = time.perf_counter()
            result = method(boxes)
            results[name]["time"].append(time.perf_counter() - start)
            results[name]["tests"].append(result.tests)
            results[name]["pairs"].append(len(result.pairs))
            if reference is None:
                reference = result.pairs
            elif result.pairs != reference:
                sys.exit(f"broadphase: {name} disagrees with brute force at N={n} ({kind})")
        start = time.perf_counter()
        tree.move_many(keys, pos, pos + size)
        result = tree.pairs()
        results[TREE]["time"].append(time.perf_counter() - start)
        results[TREE]["tests"].append(result.tests)
        results[TREE]["pairs"].append(len(result.pairs))
        if result.pairs != reference:
            sys.exit(f"broadphase: {TREE} disagrees with brute force at N={n} ({kind})")
    summary = {}
    for name, r in results.items():
        if r["time"]:
            summary[name] = {"time": statistics.median(r["time"]), "tests": statistics.mean(r["tests"]),
                             "pairs": statistics.mean(r["pairs"])}
    summary[TREE]["build"] = tree_build
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="10,30,100,300,1000,3000,10000")
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--brute-cap", type=int, default=3000,
                        help="largest N for the plain-Python brute force (it grows as N^2)")
    parser.add_argument("--plot", default=str(Path(__file__).resolve().parent.parent / "docs/images/broadphase.png"))
    parser.add_argument("--seed", type=int, default=2024)
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]

    print(f"Broad phase benchmark: {args.frames} frames per case, median time per frame; density constant "
          f"(world side {DENSITY_SIDE:g} * sqrt(N)), boxes {BOX_SIZE[0]:g}..{BOX_SIZE[1]:g} wide.")
    print(f"Plain-Python brute force runs up to N = {args.brute_cap} (it grows as N^2); above that the "
          f"ratios are against the numpy brute force, marked *.")
    print(f"AABB tree: built once (build time in brackets), then move_many() on every object each frame (margin {TREE_MARGIN:g}).\n")
    table: dict[tuple[str, int], dict[str, dict[str, float]]] = {}
    header = f"{'scene':9} {'N':>6}  {'method':20} {'overlaps':>9} {'pairs tested':>13} {'tested/brute':>12} {'ms/frame':>10} {'speed-up':>9}"
    print(header)
    print("-" * len(header))
    for kind in ("uniform", "clustered"):
        for n in sizes:
            summary = run_case(n, kind, args.frames, args.brute_cap, args.seed + n)
            table[(kind, n)] = summary
            base_name = "brute force" if "brute force" in summary else "brute force (numpy)"
            base = summary[base_name]
            for name in METHOD_ORDER:
                if name not in summary:
                    print(f"{kind:9} {n:>6}  {name:20} {'(skipped: N above --brute-cap)':>40}")
                    continue
                s = summary[name]
                mark = "" if base_name == "brute force" else "*"
                ratio_tests = s["tests"] / base["tests"] if base["tests"] else 1.0
                speedup = base["time"] / s["time"] if s["time"] else float("inf")
                extra = f"  [build {s['build'] * 1e3:.1f} ms]" if "build" in s else ""
                print(f"{kind:9} {n:>6}  {name:20} {s['pairs']:>9.0f} {s['tests']:>13.0f} {ratio_tests:>11.4f}{mark} "
                      f"{s['time'] * 1e3:>10.2f} {speedup:>8.1f}x{mark}{extra}")
        print()
    write_plot(table, sizes, Path(args.plot))
    print(f"plot: {args.plot}")
    return 0


def write_plot(table, sizes: list[int], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5), sharex=True)
    styles = {"brute force": ("k", "o", "-"), "brute force (numpy)": ("0.5", "o", "--"), "grid": ("C0", "s", "-"),
              "sort and sweep": ("C1", "^", "-"), "quadtree": ("C2", "D", "-"), TREE: ("C3", "v", "-")}
    for col, kind in enumerate(("uniform", "clustered")):
        for row, (key, label) in enumerate((("time", "time per frame (ms)"), ("tests", "pairs tested per frame"))):
            ax = axes[row][col]
            for name in METHOD_ORDER:
                if key == "tests" and name == "brute force (numpy)":
                    continue  # same count as brute force
                xs = [n for n in sizes if name in table[(kind, n)]]
                ys = [table[(kind, n)][name][key] * (1e3 if key == "time" else 1) for n in xs]
                colour, marker, line = styles[name]
                ax.loglog(xs, ys, color=colour, marker=marker, linestyle=line, label=name)
            if key == "tests":  # the brute force count N(N-1)/2 for the sizes not run in Python
                ax.loglog(sizes, [n * (n - 1) / 2 for n in sizes], color="k", linestyle=":", linewidth=1,
                          label="N(N-1)/2")
            ax.set_title(f"{kind}: {label}")
            ax.grid(True, which="both", alpha=0.3)
            if row == 1:
                ax.set_xlabel("objects N")
    axes[0][0].legend(fontsize=8)
    axes[1][0].legend(fontsize=8)
    fig.suptitle("Broad phases vs brute force (log-log; constant density)")
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90)
    plt.close(fig)
    write_atomic(path, buffer.getvalue())


if __name__ == "__main__":
    raise SystemExit(main())
