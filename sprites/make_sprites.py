"""Generate the sample sprites in this folder: raw 64-byte .spr files and PNG previews.

Run `python sprites/make_sprites.py`; the outputs are checked in. Shapes are drawn from their
geometric definitions, so they are easy to reason about in tests and in the speed/accuracy study:

hires (24x21, one bit per pixel)         multicolor (12x21 double-wide pixels, values 1-3)
  ball.spr      filled disc r=10           mc_ball.spr     disc: ring of 3, inner of 1, core of 2
  ring.spr      annulus r=10, inner r=6    mc_ship.spr     ship in colours 1/2/3
  ship.spr      arrow-head ship            mc_gem.spr      diamond with a 01 (colour 1) rim
  bullet.spr    4x4 square at (10,8)
  bar.spr       1-pixel-wide vertical bar at x=11, rows 0-20
  pentagon.spr  regular pentagon r=10
  lshape.spr    L: 4-wide stem + 4-high foot
  full.spr      every pixel opaque (the bounding box)
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from retro.render.sprite_png import write_png  # noqa: E402
from retro.sprites import encode, write_spr  # noqa: E402

WIDTH, HEIGHT, MC_WIDTH = 24, 21, 12
CENTRE_X, CENTRE_Y = 11.5, 10.0  # pixel centres are at integer + 0.5 horizontally for a 24-wide grid


def grid(width: int = WIDTH) -> tuple[np.ndarray, np.ndarray]:
    ys, xs = np.mgrid[0:HEIGHT, 0:width]
    return xs.astype(float), ys.astype(float)


def disc(radius: float) -> np.ndarray:
    xs, ys = grid()
    return (xs - CENTRE_X) ** 2 + (ys - CENTRE_Y) ** 2 <= radius ** 2


def polygon(points: list[tuple[float, float]], width: int = WIDTH) -> np.ndarray:
    """Pixels whose centre lies inside a convex polygon (either winding)."""
    xs, ys = grid(width)
    left = np.ones_like(xs, dtype=bool)
    right = np.ones_like(xs, dtype=bool)
    n = len(points)
    for i in range(n):
        (x0, y0), (x1, y1) = points[i], points[(i + 1) % n]
        cross = (x1 - x0) * (ys + 0.5 - y0) - (y1 - y0) * (xs + 0.5 - x0)
        left &= cross <= 0
        right &= cross >= 0
    return left | right


def hires_shapes() -> dict[str, np.ndarray]:
    shapes = {"ball": disc(10), "ring": disc(10) & ~disc(6)}
    shapes["ship"] = polygon([(12, 0), (23, 21), (12, 15)]) | polygon([(12, 0), (12, 15), (1, 21)])
    bullet = np.zeros((HEIGHT, WIDTH), bool)
    bullet[8:12, 10:14] = True
    shapes["bullet"] = bullet
    bar = np.zeros((HEIGHT, WIDTH), bool)
    bar[:, 11] = True
    shapes["bar"] = bar
    angles = [math.radians(-90 + 72 * k) for k in range(5)]
    shapes["pentagon"] = polygon([(12 + 10.5 * math.cos(a), 10.5 + 10.5 * math.sin(a)) for a in angles])
    lshape = np.zeros((HEIGHT, WIDTH), bool)
    lshape[0:21, 2:6] = True
    lshape[17:21, 2:20] = True
    shapes["lshape"] = lshape
    shapes["full"] = np.ones((HEIGHT, WIDTH), bool)
    return shapes


def mc_disc_rings() -> np.ndarray:
    ys, xs = np.mgrid[0:HEIGHT, 0:MC_WIDTH]
    d = np.hypot((xs + 0.5 - 6) * 2, ys - CENTRE_Y)  # double-wide pixels: x distance counts twice
    values = np.zeros((HEIGHT, MC_WIDTH), np.uint8)
    values[d <= 10.5] = 3
    values[d <= 8] = 1
    values[d <= 4] = 2
    return values


def multicolor_shapes() -> dict[str, np.ndarray]:
    ship = np.zeros((HEIGHT, MC_WIDTH), np.uint8)
    hull = polygon([(6, 0), (12, 21), (6, 15)], MC_WIDTH) | polygon([(6, 0), (6, 15), (0, 21)], MC_WIDTH)
    ship[hull] = 2
    ship[polygon([(6, 4), (8, 12), (4, 12)], MC_WIDTH)] = 3
    ship[17:21][hull[17:21]] = 1
    gem = np.zeros((HEIGHT, MC_WIDTH), np.uint8)
    outer = polygon([(6, 0), (12, 10.5), (6, 21), (0, 10.5)], MC_WIDTH)
    inner = polygon([(6, 3), (10, 10.5), (6, 18), (2, 10.5)], MC_WIDTH)
    gem[outer] = 1
    gem[inner] = 3
    return {"mc_ball": mc_disc_rings(), "mc_ship": ship, "mc_gem": gem}


def main() -> None:
    for name, mask in hires_shapes().items():
        data = encode(mask.astype(np.uint8))
        write_spr(HERE / f"{name}.spr", [data])
        write_png(HERE / "previews" / f"{name}.png", data, scale=4)
    for name, values in multicolor_shapes().items():
        data = encode(values, multicolor=True)
        write_spr(HERE / f"{name}.spr", [data])
        write_png(HERE / "previews" / f"{name}.png", data, multicolor=True, scale=4)
    print(f"wrote {len(hires_shapes()) + len(multicolor_shapes())} sprites into {HERE}")


if __name__ == "__main__":
    main()
