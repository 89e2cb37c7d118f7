def levels(rng):
    """Sixteen levels, each below 128: the branch at `check` is never taken."""
    return rng.integers(0, 128, size=16)


def high_levels():
    """Sixteen levels of 200: they contradict the fact that the branch is never taken."""
    return [200] * 16


def lookup(x, levels):
    return levels[x] if levels[x] < 128 else 255
