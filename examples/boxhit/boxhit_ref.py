"""The reference: what boxhit should answer, written from the definition (not from the assembly)."""


def boxhit(ax, ay, aw, ah, bx, by, bw, bh):
    """Box A covers x in [ax, ax + aw) and y in [ay, ay + ah); box B likewise; touching is no overlap."""
    return max(ax, bx) < min(ax + aw, bx + bw) and max(ay, by) < min(ay + ah, by + bh)
