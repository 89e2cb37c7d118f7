"""Draw the pictures in docs/geometry.md from the library itself (every number shown is computed).

    python docs/make_geometry_images.py          # writes docs/images/geometry_*.png and parry_frame.png
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle as CirclePatch, Polygon as PolygonPatch, Rectangle  # noqa: E402

from retro.fileio import write_atomic  # noqa: E402
from retro.geometry import (  # noqa: E402
    AABBTree, BoxSet, Box, Circle, RayScene, Segment, aabb_overlap, bounce, circle_aabb_overlap, closest_point_on_aabb,
    convex_decompose, mask_from_rows, mask_overlap_area, mask_overlap_mask, ray_aabb, ray_circle, ray_segment,
    regular_polygon, sat, slide, swept_aabb_hit, triangulate, simple_polygon,
)
from retro.geometry.broadphase import Quadtree, choose_cell_size, grid_pairs, sweep_and_prune_pairs  # noqa: E402
from retro.geometry.sat import project_polygon  # noqa: E402

OUT = Path(__file__).resolve().parent / "images"
BLUE, RED, GREEN, GREY, ORANGE = "#3b6fc4", "#d0493f", "#2f9e55", "#888888", "#e08a1e"


def save(fig, name: str) -> None:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=80, bbox_inches="tight")
    plt.close(fig)
    write_atomic(OUT / name, buffer.getvalue())
    print(f"wrote {OUT / name}")


def rect(ax, lo, hi, colour, fill=0.15, **kw):
    face = matplotlib.colors.to_rgba(colour, fill)
    ax.add_patch(Rectangle(lo, hi[0] - lo[0], hi[1] - lo[1], facecolor=face, edgecolor=colour, lw=2, **kw))


def poly(ax, pts, colour, fill=0.25, lw=2, **kw):
    ax.add_patch(PolygonPatch(pts, closed=True, facecolor=colour, alpha=fill, edgecolor=colour, lw=lw, **kw))
    ax.add_patch(PolygonPatch(pts, closed=True, fill=False, edgecolor=colour, lw=lw))


def setup(ax, title, xlim=None, ylim=None):
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.25)
    if xlim:
        ax.set_xlim(*xlim)
    if ylim:
        ax.set_ylim(*ylim)


def aabb_and_circle() -> None:
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    ax = axes[0]
    a, b = ((1, 1), (5, 4)), ((4, 3), (8, 6))
    rect(ax, *a, BLUE)
    rect(ax, *b, RED)
    ax.plot(*zip(a[0], a[1]), "o", color=BLUE)
    ax.annotate("min", a[0], xytext=(-4, -14), textcoords="offset points", color=BLUE)
    ax.annotate("max", a[1], xytext=(4, 2), textcoords="offset points", color=BLUE)
    c = ((a[0][0] + a[1][0]) / 2, (a[0][1] + a[1][1]) / 2)
    ax.plot(*c, "+", color=BLUE, ms=12)
    ax.annotate("", xy=(a[1][0], c[1]), xytext=c, arrowprops=dict(arrowstyle="->", color=BLUE))
    ax.text(c[0] + 0.3, c[1] + 0.15, "half.x", color=BLUE, fontsize=8)
    setup(ax, f"min/max or centre/half-size\naabb_overlap = {aabb_overlap(*a, *b)}", (0, 9), (0, 7))
    ax = axes[1]
    a, b, c2 = ((1, 1), (4, 4)), ((4, 1), (7, 4)), ((4, 4), (6, 6))
    rect(ax, *a, BLUE)
    rect(ax, *b, RED)
    rect(ax, *c2, GREEN)
    setup(ax, "touching is NOT overlapping (strict <)\n"
              f"blue-red {aabb_overlap(*a, *b)}, blue-green {aabb_overlap(*a, *c2)}", (0, 8), (0, 7))
    ax = axes[2]
    box, centre, r = ((2, 1), (6, 4)), (7.5, 5.5), 2.2
    rect(ax, *box, BLUE)
    ax.add_patch(CirclePatch(centre, r, facecolor=matplotlib.colors.to_rgba(RED, 0.2), edgecolor=RED, lw=2))
    q = closest_point_on_aabb(centre, *box)
    ax.plot(*zip(centre, q), "--", color="k")
    ax.plot(*q, "ko")
    ax.annotate("q = clamp(centre)\n= closest point", q, xytext=(8, -40), textcoords="offset points", fontsize=8)
    d = math.dist(centre, q)
    setup(ax, f"circle vs AABB: clamp the centre\n|c - q| = {d:.2f} < r = {r}: {circle_aabb_overlap(centre, r, *box)}",
          (0, 10), (0, 8))
    save(fig, "geometry_aabb_circle.png")


def sat_picture() -> None:
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.2))
    a = regular_polygon(5, 2.0, (3.0, 3.0), rotation=0.2)
    b = regular_polygon(5, 2.0, (6.3, 3.6), rotation=1.0)
    (ux, uy), depth = sat(a, b)
    ax = axes[0]
    poly(ax, a, BLUE)
    poly(ax, b, RED)
    moved = [(x + ux * depth, y + uy * depth) for x, y in a]
    poly(ax, moved, BLUE, fill=0.0, lw=1, linestyle="--")
    ca = np.mean(a, axis=0)
    ax.annotate("", xy=(ca[0] + ux * depth * 3, ca[1] + uy * depth * 3), xytext=ca,
                arrowprops=dict(arrowstyle="->", color="k", lw=2))
    ax.text(0.0, 5.6, f"MTV axis ({ux:.2f}, {uy:.2f}), depth {depth:.3f}\n(arrow drawn 3x longer)", fontsize=8)
    # The projections of both shapes on the MTV axis, as intervals on a number line below the shapes.
    spans = [project_polygon(pts, (ux, uy)) for pts in (a, b)]
    s_min = min(lo for lo, _ in spans)
    for (lo, hi), colour, y in zip(spans, (BLUE, RED), (-0.9, -1.3)):
        ax.plot([lo - s_min + 0.5, hi - s_min + 0.5], [y, y], color=colour, lw=5, solid_capstyle="butt")
    overlap_lo, overlap_hi = max(spans[0][0], spans[1][0]), min(spans[0][1], spans[1][1])
    ax.axvspan(overlap_lo - s_min + 0.5, overlap_hi - s_min + 0.5, ymin=0.0, ymax=0.14, color="k", alpha=0.15)
    ax.text(0.5, -1.95, "projections on the MTV axis (number line): their overlap (grey) is the depth", fontsize=8)
    setup(ax, "overlap: the smallest projection overlap gives the MTV\n(dashed: a moved by axis * depth, now touching)",
          (-0.5, 9), (-2.2, 6.5))
    ax = axes[1]
    b2 = regular_polygon(5, 2.0, (7.6, 3.9), rotation=1.0)
    poly(ax, a, BLUE)
    poly(ax, b2, RED)
    # find the first separating axis the same way sat() does (edge normals of a, then b)
    found = None
    for pts in (a, b2):
        ccw = simple_polygon(pts)
        for i in range(len(ccw)):
            (x0, y0), (x1, y1) = ccw[i], ccw[(i + 1) % len(ccw)]
            n = (y1 - y0, x0 - x1)
            la, ha = project_polygon(a, n)
            lb, hb = project_polygon(b2, n)
            if ha <= lb or hb <= la:
                found = (n, (x0, y0), (x1, y1))
                break
        if found:
            break
    n, e0, e1 = found
    length = math.hypot(*n)
    nx, ny = n[0] / length, n[1] / length
    mid = ((e0[0] + e1[0]) / 2, (e0[1] + e1[1]) / 2)
    ax.plot([mid[0] - ny * 5, mid[0] + ny * 5], [mid[1] + nx * 5, mid[1] - nx * 5], color=GREEN, lw=1.5)
    ax.plot(*zip(e0, e1), color=GREEN, lw=4)
    setup(ax, f"separated: sat() = {sat(a, b2)}\nthe first separating edge (green) and its line", (-0.5, 10.5), (-1, 6.5))
    save(fig, "geometry_sat.png")


def decompose_picture() -> None:
    ring = [(0, 0), (6, 0), (6, 5), (4, 5), (4, 2), (2, 2), (2, 5), (-1, 4), (1, 2.5)]
    ccw = simple_polygon(ring)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    ax = axes[0]
    poly(ax, ccw, GREY, fill=0.1)
    for tri in triangulate(ring):
        poly(ax, [ccw[i] for i in tri], BLUE, fill=0.1, lw=1)
    setup(ax, f"ear clipping: {len(ccw) - 2} triangles", (-1.5, 6.5), (-0.5, 5.5))
    ax = axes[1]
    pieces = convex_decompose(ring)
    colours = plt.cm.tab10.colors
    for k, piece in enumerate(pieces):
        poly(ax, piece, colours[k % 10], fill=0.35)
    setup(ax, f"merged across diagonals while convex: {len(pieces)} convex pieces", (-1.5, 6.5), (-0.5, 5.5))
    save(fig, "geometry_decompose.png")


def masks_picture() -> None:
    ship = mask_from_rows(["...##...", "..####..", ".######.", "########", "##.##.##", "#......#"])
    rock = mask_from_rows([".###.", "#####", "#####", ".###."])
    offset = (5, 3)
    hit = mask_overlap_mask(ship, rock, offset)
    h = max(ship.shape[0], offset[1] + rock.shape[0])
    w = max(ship.shape[1], offset[0] + rock.shape[1])
    canvas = np.ones((h, w, 3))
    canvas[: ship.shape[0], : ship.shape[1]][ship] = matplotlib.colors.to_rgb(BLUE)
    region = canvas[offset[1]: offset[1] + rock.shape[0], offset[0]: offset[0] + rock.shape[1]]
    region[rock] = matplotlib.colors.to_rgb(RED)
    canvas[: ship.shape[0], : ship.shape[1]][hit] = (0.1, 0.1, 0.1)
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.imshow(canvas, interpolation="nearest")
    ax.set_xticks(np.arange(-0.5, w, 1), minor=True)
    ax.set_yticks(np.arange(-0.5, h, 1), minor=True)
    ax.grid(which="minor", color="#cccccc", lw=0.5)
    ax.tick_params(which="both", length=0, labelbottom=False, labelleft=False)
    ax.set_title(f"masks: ship (blue), rock (red) at offset {offset}\n"
                 f"overlap pixels (black): mask_overlap_area = {mask_overlap_area(ship, rock, offset)}", fontsize=10)
    save(fig, "geometry_masks.png")


def rays_picture() -> None:
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    ax = axes[0]
    o, d = (0.5, 1.0), (1.0, 0.45)
    box, centre, r, seg = ((3, 1), (5, 4)), (8, 4.5), 1.2, ((10.5, 2.5), (11.5, 7))
    rect(ax, *box, BLUE)
    ax.add_patch(CirclePatch(centre, r, facecolor=matplotlib.colors.to_rgba(RED, 0.2), edgecolor=RED, lw=2))
    ax.plot(*zip(*seg), color=GREEN, lw=3)
    ax.annotate("", xy=(o[0] + 12 * d[0], o[1] + 12 * d[1]), xytext=o, arrowprops=dict(arrowstyle="->", lw=1.5))
    ax.plot(*o, "ko")
    te, tx = ray_aabb(o, d, *box)
    t1, t2 = ray_circle(o, d, centre, r)
    ts = ray_segment(o, d, *seg)
    for t, label, colour, shift in ((te, "t_enter", BLUE, (4, -14)), (tx, "t_exit", BLUE, (4, -14)),
                                    (t1, "t1", RED, (-10, 8)), (t2, "t2", RED, (-10, 8)), (ts, "t", GREEN, (6, -12))):
        p = (o[0] + t * d[0], o[1] + t * d[1])
        ax.plot(*p, "o", color=colour)
        ax.annotate(f"{label}={t:.2f}", p, xytext=shift, textcoords="offset points", fontsize=8, color=colour)
    for x in box[0][0], box[1][0]:
        ax.axvline(x, color=BLUE, alpha=0.3, ls="--")
    for y in box[0][1], box[1][1]:
        ax.axhline(y, color=BLUE, alpha=0.3, ls="--")
    setup(ax, "ray_aabb (slabs, dashed), ray_circle (two roots), ray_segment", (0, 13), (0, 8))
    ax = axes[1]
    rng = np.random.default_rng(3)
    shapes = []
    for _ in range(60):
        p = rng.uniform(0, 100, 2)
        k = rng.integers(3)
        shapes.append(Box(tuple(p), tuple(p + rng.uniform(2, 7, 2))) if k == 0 else
                      Circle(tuple(p), float(rng.uniform(1, 4))) if k == 1 else
                      Segment(tuple(p), tuple(p + rng.uniform(-8, 8, 2))))
    scene = RayScene(shapes)
    origin, direction = (2.0, 8.0), (1.0, 0.62)
    hit = scene.first_hit(origin, direction)
    for (x0, y0, x1, y1), depth, leaf in scene.tree.nodes():
        if not leaf:
            ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor=GREY, lw=0.6, alpha=0.6))
    for i, s in enumerate(shapes):
        colour, width = (ORANGE, 3) if i == hit.index else ("k", 1.5)
        if isinstance(s, Box):
            rect(ax, s.min, s.max, colour, fill=0.2)
        elif isinstance(s, Circle):
            ax.add_patch(CirclePatch(s.center, s.radius, facecolor=matplotlib.colors.to_rgba(colour, 0.2),
                                     edgecolor=colour, lw=width))
        else:
            ax.plot(*zip(s.a, s.b), color=colour, lw=width)
    ax.plot(*zip(origin, hit.point), color=RED, lw=2)
    ax.plot(*hit.point, "o", color=RED)
    setup(ax, f"first hit among {len(shapes)} shapes through the AABB tree (grey: tree nodes)\n"
              f"hit shape {hit.index} (orange) at t = {hit.t:.2f}; exact tests: {hit.shapes_tested} of {len(shapes)}", (-2, 108), (-2, 108))
    save(fig, "geometry_rays.png")


def swept_picture() -> None:
    fig, ax = plt.subplots(figsize=(9, 3.6))
    lo, hi, v = (0.0, 1.0), (1.5, 2.5), (14.0, 1.5)
    wall = ((7.0, -0.5), (7.4, 5.0))
    rect(ax, *wall, GREY, fill=0.5)
    rect(ax, lo, hi, BLUE, fill=0.15)
    rect(ax, (lo[0] + v[0], lo[1] + v[1]), (hi[0] + v[0], hi[1] + v[1]), BLUE, fill=0.05, linestyle="--")
    hit = swept_aabb_hit(lo, hi, v, *wall)
    rect(ax, (lo[0] + hit.t * v[0], lo[1] + hit.t * v[1]), (hi[0] + hit.t * v[0], hi[1] + hit.t * v[1]), RED, fill=0.3)
    ax.annotate("", xy=(lo[0] + v[0], lo[1] + v[1]), xytext=lo, arrowprops=dict(arrowstyle="->", lw=1.2))
    ax.text(0, 3.2, "t = 0", color=BLUE)
    ax.text(17, 4.6, "t = 1 (a discrete test sees no overlap at either end)", color=BLUE, fontsize=8, ha="right")
    ax.text(lo[0] + hit.t * v[0] - 1.5, 3.6, f"contact t = {hit.t:.3f}\nnormal {hit.normal}", color=RED, fontsize=9)
    setup(ax, "swept_aabb: time of first contact within the frame (no tunnelling through the thin wall)", (-1, 17.5), (-1, 5.5))
    save(fig, "geometry_swept.png")


def broadphase_picture() -> None:
    rng = np.random.default_rng(5)
    n = 70
    centres = rng.uniform(0, 100, (3, 2))
    pos = np.vstack([rng.uniform(0, 100, (n // 2, 2)), centres[rng.integers(0, 3, n - n // 2)] + rng.normal(0, 6, (n - n // 2, 2))])
    size = rng.uniform(2, 8, (n, 2))
    boxes = BoxSet.from_arrays(pos, pos + size)
    pairs = set(grid_pairs(boxes).pairs)
    hit_ids = {i for p in pairs for i in p}
    fig, axes = plt.subplots(2, 2, figsize=(11, 11))

    def draw_boxes(ax):
        for i in range(n):
            rect(ax, pos[i], pos[i] + size[i], RED if i in hit_ids else BLUE, fill=0.25)

    ax = axes[0][0]
    cell = choose_cell_size(boxes)
    occupied = {}
    for i in range(n):
        for cx in range(int(pos[i][0] // cell), int((pos[i][0] + size[i][0]) // cell) + 1):
            for cy in range(int(pos[i][1] // cell), int((pos[i][1] + size[i][1]) // cell) + 1):
                occupied[(cx, cy)] = occupied.get((cx, cy), 0) + 1
    for (cx, cy), count in occupied.items():
        ax.add_patch(Rectangle((cx * cell, cy * cell), cell, cell, facecolor=ORANGE, alpha=min(0.1 * count, 0.6)))
    for k in range(int(110 // cell) + 1):
        ax.axvline(k * cell, color=GREY, lw=0.4)
        ax.axhline(k * cell, color=GREY, lw=0.4)
    draw_boxes(ax)
    setup(ax, f"uniform grid / spatial hash: cell {cell:.1f} (largest box)\n"
              f"{grid_pairs(boxes).tests} pairs tested, {len(pairs)} overlapping (red)", (-2, 110), (-2, 110))
    ax = axes[0][1]
    order = np.argsort(pos[:, 0])
    for rank, i in enumerate(order):
        y = -2 - (rank % 6) * 1.2
        ax.plot([pos[i][0], pos[i][0] + size[i][0]], [y, y], color=RED if i in hit_ids else BLUE, lw=2)
    draw_boxes(ax)
    setup(ax, f"sort and sweep on x: intervals [min.x, max.x) sorted by start\n"
              f"{sweep_and_prune_pairs(boxes, 0).tests} pairs tested", (-2, 110), (-10, 110))
    ax = axes[1][0]
    tree = Quadtree(boxes, capacity=4)
    for x0, y0, x1, y1 in tree.nodes():
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor=GREEN, lw=0.8))
    draw_boxes(ax)
    setup(ax, f"quadtree (capacity 4, depth {tree.depth()}): boxes live in the smallest node containing them\n"
              f"{tree.pairs().tests} pairs tested", (-2, 110), (-2, 110))
    ax = axes[1][1]
    aabb = AABBTree()
    for i in range(n):
        aabb.insert(i, pos[i], pos[i] + size[i])
    cmap = plt.cm.viridis
    for (x0, y0, x1, y1), depth, leaf in aabb.nodes():
        if not leaf:
            ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False,
                                   edgecolor=cmap(depth / max(aabb.height, 1)), lw=1.6 - depth * 0.12))
    draw_boxes(ax)
    setup(ax, f"dynamic AABB tree (height {aabb.height}, colour = depth)\n{aabb.pairs().tests} pairs tested",
          (-2, 110), (-2, 110))
    save(fig, "geometry_broadphase.png")


def response_picture() -> None:
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    n = (-1.0, 0.0)  # from b (right) to a (left)
    for ax, e in zip(axes[:2], (1.0, 0.0)):
        va, vb = (3.0, 1.0), (-1.0, 0.0)
        na, nb = bounce(va, vb, n, e, 1.0, 2.0)
        pa, pb = (2.0, 2.0), (4.0, 2.0)
        ax.add_patch(CirclePatch(pa, 1, facecolor=matplotlib.colors.to_rgba(BLUE, 0.2), edgecolor=BLUE, lw=2))
        ax.add_patch(CirclePatch(pb, 1, facecolor=matplotlib.colors.to_rgba(RED, 0.2), edgecolor=RED, lw=2))
        for p, v, colour, ls in ((pa, va, BLUE, ":"), (pb, vb, RED, ":"), (pa, na, BLUE, "-"), (pb, nb, RED, "-")):
            ax.annotate("", xy=(p[0] + v[0], p[1] + v[1]), xytext=p,
                        arrowprops=dict(arrowstyle="->", color=colour, lw=2, linestyle=ls))
        setup(ax, f"bounce, restitution {e:g}, masses 1 (blue), 2 (red)\nbefore dotted, after solid\n"
                  f"after: a {tuple(round(x, 2) for x in na)}, b {tuple(round(x, 2) for x in nb)}", (-2, 8), (-1, 5))
    ax = axes[2]
    ax.add_patch(Rectangle((-1, -1), 8, 1, facecolor=GREY, alpha=0.5))
    v = (3.0, -2.0)
    s = slide(v, (0.0, 1.0))
    p = (1.0, 2.0)
    ax.annotate("", xy=(p[0] + v[0], p[1] + v[1]), xytext=p, arrowprops=dict(arrowstyle="->", color=BLUE, lw=2, linestyle=":"))
    ax.annotate("", xy=(p[0] + s[0], p[1] + s[1]), xytext=p, arrowprops=dict(arrowstyle="->", color=BLUE, lw=2))
    setup(ax, f"slide: remove the normal part\n{v} -> {s}", (-1, 7), (-1, 4))
    save(fig, "geometry_response.png")


def parry_picture() -> None:
    from retro.commands.parry import DEFAULT_SCRIPT, parse_script
    from retro.geometry.parry import DEFAULT_FRAMES, simulate
    from retro.render.images import png_bytes
    from retro.render.parry import render_frame

    states = simulate(parse_script(DEFAULT_SCRIPT), DEFAULT_FRAMES)
    for state in states:
        if any(e.kind == "parry" for e in state.events):
            write_atomic(OUT / "parry_frame.png", png_bytes(render_frame(states, state.frame).convert("RGB")))
            print(f"wrote {OUT / 'parry_frame.png'}")
            return


if __name__ == "__main__":
    aabb_and_circle()
    sat_picture()
    decompose_picture()
    masks_picture()
    rays_picture()
    swept_picture()
    broadphase_picture()
    response_picture()
    parry_picture()
