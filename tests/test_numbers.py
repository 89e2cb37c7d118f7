"""parse_int: every notation a user may type, and the errors for the rest."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from retro.errors import InputError
from retro.numbers import parse_address, parse_byte, parse_int


@given(st.integers(min_value=0, max_value=0xFFFF))
def test_every_notation_reads_back(value):
    for text in (f"${value:X}", f"${value:x}", f"0x{value:x}", f"0X{value:X}", f"%{value:b}", f"0b{value:b}",
                 str(value), f"  {value}  "):
        assert parse_int(text) == value, text


def test_examples_from_the_cli_help():
    assert parse_int("$C000") == parse_int("0xc000") == parse_int("49152") == 0xC000
    assert parse_int("%1010") == 10
    assert parse_int("-5") == -5
    assert parse_int(7) == 7


@pytest.mark.parametrize("text", ["", "$", "0x", "%2", "12a", "$G0", "ten", "1.5", "--5", "$-5", "+5", "0x-1"])
def test_not_a_number(text):
    with pytest.raises(InputError, match="^--a: not a number"):
        parse_int(text, field="--a")


def test_bool_is_not_a_number():
    with pytest.raises(InputError):
        parse_int(True)


@pytest.mark.parametrize("text, lo, hi", [("256", 0, 255), ("-1", 0, 255), ("$10000", 0, 0xFFFF), ("0", 1, None)])
def test_out_of_range_names_field_and_range(text, lo, hi):
    with pytest.raises(InputError) as error:
        parse_int(text, field="--x", lo=lo, hi=hi)
    assert str(error.value).startswith("--x: ") and "out of range" in str(error.value)


def test_byte_and_address_helpers():
    assert parse_byte("$FF") == 255 and parse_address("$FFFF") == 0xFFFF
    with pytest.raises(InputError):
        parse_byte("$100")
    with pytest.raises(InputError):
        parse_address(0x10000)
