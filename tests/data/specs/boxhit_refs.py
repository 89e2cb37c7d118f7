"""Reference of the boxhit fixtures (tests/data/foreign/*_boxhit.*): two boxes share a pixel.

Written from the definition, not from the assembly: box A covers x in [ax, ax + aw), box B
[bx, bx + bw), and likewise in y; touching boxes share no pixel.
"""


def boxhit(ax, ay, aw, ah, bx, by, bw, bh):
    return max(ax, bx) < min(ax + aw, bx + bw) and max(ay, by) < min(ay + ah, by + bh)
