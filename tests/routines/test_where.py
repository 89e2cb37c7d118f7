"""A spec's `where` means what Python means, on both engines: no wrap, no numpy division by zero, no
silent negative shifts, nothing built without bound, no recursion; and a domain that excludes every
case is an error, not an OK having checked nothing."""

from __future__ import annotations

import random
import time

import numpy as np
import pytest

from retro.cli import main
from retro.errors import InputError
from retro.routines.where import MAX_DEPTH, parse_where

from test_user_code import spec

NAMES = ("ax", "bx")
BOUNDS = {"ax": (-300, 300), "bx": (0, 1 << 32)}


def columns(n: int = 400, seed: int = 1) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    edges = np.array([0, 1, -1, 2, 63, 64, -300, 300], dtype=np.int64)
    ax = np.concatenate([edges, rng.integers(-300, 301, n)])
    bx = np.concatenate([np.array([0, 1, 2, 3, 63, 64, 1 << 32, (1 << 32) - 1]), rng.integers(0, 1 << 32, n)])
    return [ax, bx]


def python_answer(text: str, cols: list[np.ndarray]):
    """The whole expression, case by case, in Python itself: a list of bools, or the error's type."""
    out = []
    for ax, bx in zip(*(c.tolist() for c in cols)):
        try:
            out.append(bool(eval(text, {"__builtins__": {}, "abs": abs, "min": min, "max": max}, {"ax": ax, "bx": bx})))
        except (ArithmeticError, ValueError) as exc:
            return type(exc)
    return out


def retro_answer(text: str, cols: list[np.ndarray], by_case: bool = False):
    try:
        conditions = parse_where(text, NAMES, "spec.toml: cases.where", bounds=BOUNDS)
        if by_case:
            cases = list(zip(*(c.tolist() for c in cols)))
            held = [[bool(c.test(*case)) for case in cases] for c in conditions]
        else:
            held = [c.over(cols) for c in conditions]
        return np.logical_and.reduce([np.asarray(h) for h in held]).tolist()
    except InputError as exc:
        return str(exc)


@pytest.mark.parametrize("text", [
    "(ax or 5) > 3", "(ax and bx) == bx", "ax * bx * bx > 7", "bx * bx * bx * bx > 1 << 60",
    "(bx << 40) + ax > 5", "ax >> 70 == -1", "ax >> 63 == ax // (1 << 63)", "bx and ax // bx > 1",
    "(ax // bx if bx else 0) >= 0", "ax % 7 == 3 and ax // -7 < 2", "~(ax > 0) == -2", "-(bx > 0) < 0",
    "min(ax, bx, 3) == 3 or abs(ax) > 250", "1 < ax < bx // 3", "(True + True) * ax > 2",
])
def test_every_engine_answers_as_python(text):
    cols = columns()
    expected = python_answer(text, cols)
    assert isinstance(expected, list)
    assert retro_answer(text, cols) == expected
    assert retro_answer(text, cols, by_case=True) == expected


@pytest.mark.parametrize("text, term, reason, case", [
    ("ax // 0 == 0", "ax // 0 == 0", "division by zero", "at ax=0, bx=0"),
    ("ax % bx == 1", "ax % bx == 1", "division by zero", "at ax=0, bx=0"),
    ("ax >> -1 > 0", "ax >> -1 > 0", "negative shift count", "at ax=0, bx=0"),
    ("ax >= 0 and bx >> (ax - 5) > 0", "bx >> (ax - 5) > 0", "negative shift count", "at ax=0, bx=0"),
])
def test_errors_name_the_expression_and_the_case(text, term, reason, case):
    for by_case in (False, True):
        answer = retro_answer(text, columns(), by_case)
        assert isinstance(answer, str) and answer.startswith(f"spec.toml: cases.where: {term}: "), answer
        assert reason in answer and answer.endswith(case), answer


def test_random_expressions_match_python():
    """300 random expressions over both inputs: the columns, the cases and Python agree, errors included."""
    rng = random.Random(20)
    leaves = ["ax", "bx", "0", "1", "3", "-2", "255", "True"]
    binary = ["+", "-", "*", "//", "%", "&", "|", "^", ">>"]

    def expression(depth: int) -> str:
        if depth == 0 or rng.random() < 0.25:
            return rng.choice(leaves)
        kind = rng.random()
        if kind < 0.55:
            return f"({expression(depth - 1)} {rng.choice(binary)} {expression(depth - 1)})"
        if kind < 0.65:
            return f"({expression(depth - 1)} << {rng.randint(0, 40)})"
        if kind < 0.75:
            return f"({rng.choice(['-', '~', 'not '])}{expression(depth - 1)})"
        if kind < 0.85:
            return f"({expression(depth - 1)} {rng.choice(['and', 'or'])} {expression(depth - 1)})"
        if kind < 0.92:
            return f"({expression(depth - 1)} if {expression(depth - 1)} else {expression(depth - 1)})"
        return f"{rng.choice(['min', 'max'])}({expression(depth - 1)}, {expression(depth - 1)})"

    cols = columns(100)
    compared = errors = 0
    for _ in range(300):
        text = f"{expression(4)} {rng.choice(['<', '<=', '==', '!=', '>'])} {expression(3)}"
        expected = python_answer(text, cols)
        for by_case in (False, True):
            got = retro_answer(text, cols, by_case)
            if isinstance(expected, list):
                assert got == expected, (text, by_case)
            else:  # Python raised on some case: so must retro, in one line naming the expression
                assert isinstance(got, str) and "spec.toml: cases.where: " in got and "\n" not in got, (text, got)
        compared += 1
        errors += not isinstance(expected, list)
    assert errors > 10 and compared - errors > 100  # both kinds were exercised


@pytest.mark.parametrize("text, message", [
    ("len([0] * (1 << 28)) > 0", "arithmetic takes numbers, not a table or list"),
    ("ax in [0] * 99999999", "arithmetic takes numbers"),
    ("-" * 1990 + "ax > 0", f"nests more than {MAX_DEPTH} deep"),
    ("(" * 150 + "ax" + " + 1)" * 150 + " > 0", f"nests more than {MAX_DEPTH} deep"),
    ("not " * 450 + "ax", f"nests more than {MAX_DEPTH} deep"),
    ("ax << bx > 0", "a left shift must be by a constant"),
    ("ax < [1, 2]", "compare numbers, not tables or lists"),
    ("abs", "abs is a function"),
])
def test_what_could_grow_or_recurse_is_refused_when_read(text, message):
    start = time.monotonic()
    with pytest.raises(InputError) as caught:
        parse_where(text, NAMES, "spec.toml: cases.where", bounds=BOUNDS)
    assert message in str(caught.value) and "\n" not in str(caught.value)
    assert time.monotonic() - start < 5


def _check(tmp_path, where: str, *args: str) -> int:
    path = spec(tmp_path)
    named = path.with_name(f"spec{abs(hash((where, args)))}.toml")  # a new file: specs are cached by path and time
    named.write_text(path.read_text().replace("[cases]", f"[cases]\nwhere = \"{where}\""))
    return main(["check", str(named), "--jobs", "1", *args])


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_division_by_zero_in_the_domain_stops_the_check(tmp_path, capsys, engine):
    assert _check(tmp_path, "aw >= 1 and ax // (bw - bw) == 0", "--engine", engine) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cases.where: ax // (bw - bw) == 0: ax // (bw - bw): division by zero at ax=" in err


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_domain_that_excludes_every_case_is_no_ok(tmp_path, capsys, engine):
    # numpy made `ax >> -1` 0, so every case fell outside and the check said OK: now it is refused
    assert _check(tmp_path, "ax >> -1 > 0", "--engine", engine) == 2
    assert "negative shift count" in capsys.readouterr().err
    # ax's values are 1..100: the random cases, drawn inside the domain, find no value of ax there
    assert _check(tmp_path, "aw >= 1 and ax > 200", "--engine", engine) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cases.where: no value of ax within its values lies inside the domain" in err \
        and "nothing can be checked" in err, err
    assert _check(tmp_path, "aw >= 1 and ax > 90", "--engine", engine) == 0  # some inside: checked, fine
