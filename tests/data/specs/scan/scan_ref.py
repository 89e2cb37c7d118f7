"""Reference of scan.s, from its definition."""

NONE = 0xFF


def scan(key, carry, enemies, bonus):
    index = next((i for i, x in enumerate(enemies) if x == key), NONE)
    return {"index": index, "total": sum(enemies) + (bonus[0] if carry else 0)}


def edges():
    """The cheapest case (carry clear, found at once, no sum carries) and the dearest (carry set,
    none found, every addition carries)."""
    return [{"key": 0, "carry": 0, "enemies": (0,) * 8},
            {"key": 0, "carry": 1, "enemies": (255,) * 8}]
