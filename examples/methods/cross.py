"""A hitbox rule for examples/methods/cross.toml: each sprite is reduced to a cross, the middle row
and the middle column of its opaque pixels' bounding box; two sprites collide when the crosses share
a pixel.

hit(a, b, dx, dy): a and b are the sprites' opacity masks (numpy bool [y, x], screen pixels), dx
and dy numpy int arrays, one entry per case: b's top-left pixel relative to a's. Return one verdict
per case (True/False, or a share of hits in [0, 1]).
"""

import numpy as np


def cross(mask):
    ys, xs = np.nonzero(mask)
    x0, x1, y0, y1 = xs.min(), xs.max(), ys.min(), ys.max()
    cx, cy = (x0 + x1) // 2, (y0 + y1) // 2
    return {(x, cy) for x in range(x0, x1 + 1)} | {(cx, y) for y in range(y0, y1 + 1)}


def hit(a, b, dx, dy):
    pa, pb = cross(a), cross(b)
    return np.array([any((x + int(i), y + int(j)) in pa for x, y in pb) for i, j in zip(dx, dy)])
