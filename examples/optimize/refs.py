"""References of the superoptimiser's examples (docs/optimize.md): what each routine must compute."""


def umax(a, m):
    return max(a, m)


def umin(a, m):
    return min(a, m)


def absdiff(a, m):
    return abs(a - m)


def clamp(a):
    return min(a, 199)


def overlap8(a, b):
    return int(abs(a - b) >= 8)  # the carry: set when two 8-pixel spans miss


def sum_x(a, b):
    return (a + b) & 0xFF


def copy_b(b):
    return b


def sum3(a, b, c):
    return (a + b + c) & 0xFF


def times3(a):
    return (3 * a) & 0xFF


def times3_table():
    return bytes(times3(a) for a in range(256))
