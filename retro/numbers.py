"""One parser for every number a user types: "$C000", "0xc000", "%1010", "49152"."""

from __future__ import annotations

from retro.errors import InputError


def parse_int(text: str | int, *, field: str = "value", lo: int | None = None, hi: int | None = None) -> int:
    """Parse a number written as $hex, 0xhex, %binary or decimal; check it lies in [lo, hi]."""
    if isinstance(text, bool):
        raise InputError(f"{field}: expected a number, got {text!r}")
    if isinstance(text, int):
        value = text
    else:
        s = str(text).strip().replace("_", "")
        negative = s.startswith("-")
        body = s[1:] if negative else s
        try:
            if body.startswith("$"):
                value = int(body[1:], 16)
            elif body.lower().startswith("0x"):
                value = int(body[2:], 16)
            elif body.startswith("%"):
                value = int(body[1:], 2)
            elif body.lower().startswith("0b"):
                value = int(body[2:], 2)
            else:
                value = int(body, 10)
        except ValueError:
            raise InputError(f"{field}: not a number: {text!r} (use $C000, 0xc000, %1010 or 49152)") from None
        if negative:
            value = -value
    if lo is not None and value < lo or hi is not None and value > hi:
        raise InputError(f"{field}: {text!r} is out of range {fmt_range(lo, hi)}")
    return value


def fmt_range(lo: int | None, hi: int | None) -> str:
    return f"{lo if lo is not None else '-inf'}..{hi if hi is not None else 'inf'}"


def parse_byte(text: str | int, field: str = "value") -> int:
    return parse_int(text, field=field, lo=0, hi=0xFF)


def parse_address(text: str | int, field: str = "address") -> int:
    return parse_int(text, field=field, lo=0, hi=0xFFFF)
