"""The reference of absdiff: plain values, wherever the caller pushed them."""


def absdiff(s, first, second):
    return abs(first - second)
