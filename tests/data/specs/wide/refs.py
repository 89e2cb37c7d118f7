"""The reference of wide.toml."""


def wide(value):
    return {"high": ((value >> 8) + 1) & 0xFF, "low": value & 0xFF}
