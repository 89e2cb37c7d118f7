"""The reference of hit_slot: the object's position as plain values, whichever slot holds it."""


def near(a, b):
    return (a - b + 7) % 256 < 15  # |a - b| < 8, positions modulo 256


def hit_slot(slot, x, y, player_x, player_y):
    return near(x, player_x) and near(y, player_y)
