"""mul8's every product, yielded as column blocks of one row of a each (a sweep that says no count)."""

import numpy as np


def sweep():
    b = np.arange(256)
    for a in range(256):
        yield {"a": np.full(256, a), "b": b}
