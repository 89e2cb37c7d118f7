"""The reference: what hit65 should answer, written from the definition (not from the assembly)."""


def hit65(ax, ay, aw, ah, bx, by, bw, bh):
    """Box A covers x in [ax, ax + aw) and y in [ay, ay + ah); box B likewise; touching is no overlap."""
    return int(max(ax, bx) < min(ax + aw, bx + bw) and max(ay, by) < min(ay + ah, by + bh))
