def seven(table, index):
    """smc_page's answer: every byte of its tables is 7 (the spec's [memory] fill)."""
    return 7


def zero(carry, x):
    """smc_some's answer: its page is filled with zeros."""
    return 0
