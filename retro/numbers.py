"""One parser for every number a user types: "$C000", "0xc000", "%1010", "49152"."""

from __future__ import annotations

import re

from retro.errors import InputError

_NUMBER = re.compile(r"^(?P<sign>-)?(?:\$(?P<hex>[0-9a-fA-F]+)|0[xX](?P<hex0x>[0-9a-fA-F]+)"
                     r"|%(?P<binary>[01]+)|0[bB](?P<binary0b>[01]+)|(?P<decimal>[0-9]+))$")
_BASES = {"hex": 16, "hex0x": 16, "binary": 2, "binary0b": 2, "decimal": 10}
MAX_DIGITS = 80  # no number retro takes needs more; Python refuses int() of 4,300+ decimal digits


def parse_int(text: str | int, *, field: str = "value", lo: int | None = None, hi: int | None = None) -> int:
    """Parse a number written as $hex, 0xhex, %binary or decimal; check it lies in [lo, hi]."""
    if isinstance(text, bool):
        raise InputError(f"{field}: expected a number, got {text!r}")
    if isinstance(text, int):
        value = text
    else:
        if len(str(text)) > MAX_DIGITS:
            raise InputError(f"{field}: not a number: {str(text)[:20]!r}... ({len(str(text))} characters)")
        match = _NUMBER.match(str(text).strip().replace("_", ""))
        if not match:
            raise InputError(f"{field}: not a number: {text!r} (use $C000, 0xc000, %1010 or 49152)")
        base, digits = next((_BASES[name], digits) for name, digits in match.groupdict().items()
                            if digits is not None and name != "sign")
        value = int(digits, base) * (-1 if match.group("sign") else 1)
    if lo is not None and value < lo or hi is not None and value > hi:
        raise InputError(f"{field}: {text!r} is out of range {fmt_range(lo, hi)}")
    return value


def fmt_range(lo: int | None, hi: int | None) -> str:
    return f"{lo if lo is not None else '-inf'}..{hi if hi is not None else 'inf'}"


def parse_byte(text: str | int, field: str = "value") -> int:
    return parse_int(text, field=field, lo=0, hi=0xFF)


def parse_address(text: str | int, field: str = "address") -> int:
    return parse_int(text, field=field, lo=0, hi=0xFFFF)
