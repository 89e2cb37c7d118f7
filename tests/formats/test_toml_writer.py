"""retro.fileio.toml_text, the one TOML writer: whatever it writes, `parse_toml` (the reader every
input goes through) reads back equal, in every layout (sections, or tables inline below a depth)."""

from __future__ import annotations

import datetime
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from retro.fileio import parse_toml, toml_text, toml_value

LAYOUTS = (None, 0, 1, 2)


def _read(text: str) -> dict:
    return parse_toml(text.encode("utf-8"), "written.toml")


@pytest.mark.parametrize("tables", LAYOUTS)
def test_awkward_strings_and_keys_come_back_as_they_were(tables):
    doc = {"quote": 'say "hi"', "backslash": "C:\\path\\n", "newline": "a\nb\r\nc", "tab": "\tx",
           "controls": "\x00\x01\x1b\x7f", "unicode": "é😀\u2028", "hex": "0x10", "dollar": "$d015",
           "percent": "%1010", "number": "255", "bool_word": "true", "empty": "", "triple": '"""',
           "single": "'x'", "": "empty key", "a.b": "dotted key", "key with space": 1, "é": 2, "$d015": 3,
           "[x]": 4, "#": "not a comment"}
    assert _read(toml_text(doc, tables)) == doc


@pytest.mark.parametrize("tables", LAYOUTS)
def test_numbers_booleans_dates_and_nested_tables_come_back(tables):
    doc = {"int": 0, "neg": -1, "big": 2 ** 63 - 1, "small": -(2 ** 63), "float": 1.5, "exp": 1e16, "tiny": 5e-324,
           "neg_zero": -0.0, "inf": math.inf, "minus_inf": -math.inf, "yes": True, "no": False,
           "date": datetime.date(1979, 5, 27), "when": datetime.datetime(1979, 5, 27, 7, 32, 0, 999000),
           "zoned": datetime.datetime(1979, 5, 27, 7, 32, tzinfo=datetime.timezone(datetime.timedelta(hours=-7))),
           "time": datetime.time(7, 32, 1),
           "table": {"x": 1, "inner": {"bytes": 2, "deeper": {"y": "z"}}, "list": [1, "two", [3.0]]},
           "empty_table": {}, "empty_list": [], "only_tables": {"a": {"b": {}}}}
    assert _read(toml_text(doc, tables)) == doc


@pytest.mark.parametrize("tables", LAYOUTS)
def test_arrays_of_tables_and_mixed_arrays_come_back(tables):
    doc = {"sprite": [{"x": 1, "rows": ["..##", "##.."]}, {"x": 2, "frame": {"n": 0}, "sub": [{"k": 1}, {}]}],
           "mixed": [1, {"a": 1}, "s"], "in_table": {"oam": [{"y": 1}, {"y": 2}]}, "nested_lists": [[{"a": 1}]]}
    assert _read(toml_text(doc, tables)) == doc


def test_sections_down_to_the_depth_asked_and_inline_below():
    doc = {"name": "x", "inputs": {"a": {"bytes": 1}}, "cases": [{"a": 1}]}
    assert toml_text(doc, 1) == 'name = "x"\n\n[inputs]\na = { bytes = 1 }\n\n[[cases]]\na = 1\n'
    assert toml_text(doc) == 'name = "x"\n\n[inputs]\n\n[inputs.a]\nbytes = 1\n\n[[cases]]\na = 1\n'
    assert toml_text(doc, 0) == 'name = "x"\ninputs = { a = { bytes = 1 } }\ncases = [{ a = 1 }]\n'
    assert toml_text({}) == ""


def test_a_value_toml_has_no_word_for_is_refused():
    with pytest.raises(TypeError, match="no TOML for set"):
        toml_value({1, 2})


KEYS = st.text(max_size=8)
SCALARS = (st.text(max_size=12) | st.integers(-(2 ** 64), 2 ** 64) | st.booleans()
           | st.floats(allow_nan=False) | st.dates())
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(KEYS, inner, max_size=4),
                      max_leaves=20)


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(KEYS, VALUES, max_size=6), st.sampled_from(LAYOUTS))
def test_any_document_comes_back_equal(doc, tables):
    assert _read(toml_text(doc, tables)) == doc


@given(st.floats(allow_infinity=False, allow_nan=True))
def test_nan_comes_back_as_nan(value):
    back = _read(toml_text({"v": value}))["v"]
    assert back == value or math.isnan(back) and math.isnan(value)
