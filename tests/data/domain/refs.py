"""References of the domain fixtures, written from what each routine is meant to do."""


def _decimal(bcd: int) -> int:
    return int(f"{bcd:04x}")


def bcd_add(a, b):
    total = _decimal(a) + _decimal(b)
    return {"sum": int(str(total % 10000), 16), "carry": int(total > 9999)}


def add8(a, b):
    return (a + b) & 0xFF


def add8_small_only(a, b):
    """Right for a < 8 only: the cases with a >= 8 (the random part's) show it wrong."""
    return (a + b) & 0xFF if a < 8 else 0
