"""Cases that follow the domain (issue 23 part 4): `where` drives the random draw when uniform draws
would keep a small share of it, and a spec gives each part of the cases its own values."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from retro.cli import main
from retro.errors import InputError
from retro.routines import cases as case_sets
from retro.routines.registry import get
from retro.testing import spec_from_dict

DOMAIN = Path(__file__).resolve().parents[1] / "data" / "domain"
ADD = DOMAIN.parent / "entry" / "add_bcd.s"  # a + b with CLC (and no CLD: the specs state d = 0)
ENGINES = ("scalar", "batch")


def _check(capsys, spec, *args) -> tuple[int, dict]:
    code = main(["check", str(spec), "--json", "--jobs", "1", *args])
    (record,) = json.loads(capsys.readouterr().out)
    return code, record


def _bcd(value: int) -> bool:
    return all((value >> shift) & 15 <= 9 for shift in range(0, 16, 4))


def _cases(routine, part: str) -> list[tuple]:
    (found,) = [p for p in case_sets.plan(routine, exhaustive=False) if p.name == part]
    return list(found.cases)


def test_a_bcd_routines_random_cases_all_lie_inside_its_domain(capsys):
    routine = get(str(DOMAIN / "bcd_add.toml"))
    cases = _cases(routine, "random")
    assert len(cases) == 2000 and all(_bcd(a) and _bcd(b) for a, b in cases)
    assert len(set(cases)) > 1990  # drawn, not one case repeated
    code, record = _check(capsys, DOMAIN / "bcd_add.toml")
    draw = record["random_draw"]
    assert code == 0 and record["cases"] == 2000 and record["outside_domain"] == 0
    assert draw["inside"] and draw["drawn"] == 2000 and 0.015 < draw["share"] < 0.035  # (10/16)^8 = 2.3%
    # without the domain-driven draw, uniform random cases keep about 2.3% of them
    uniform = spec_from_dict({**_bcd_doc(), "cases": {**_bcd_doc()["cases"], "random_inside": False}}, base=DOMAIN)
    assert sum(_bcd(a) and _bcd(b) for a, b in _cases(uniform, "random")) < 100


def _bcd_doc() -> dict:
    import tomllib

    return tomllib.loads((DOMAIN / "bcd_add.toml").read_text())


def _pair_spec(where: str, random: int = 1000, **cases) -> dict:
    return {"program": {"file": "../entry/add_bcd.s", "entry": "add_bcd"}, "inputs": {"a": "A", "b": "b_val"},
            "outputs": {"sum": "sum"}, "reference": {"function": "refs.py:add8"},
            "cases": {"random": random, "where": where, **cases}, "entry": {"d": 0}}


@pytest.mark.parametrize("where, test, method", [
    ("a + b == 300", lambda a, b: a + b == 300, "enumerated"),  # 211 of 65,536: 0.3%
    ("a >= 250 and b < 3", lambda a, b: a >= 250 and b < 3, "enumerated"),  # 18 of 65,536
    ("(a ^ b) & 0xff == 0 and a > 10", lambda a, b: a == b and a > 10, "enumerated"),  # 245
])
def test_a_domain_of_under_one_percent_still_gets_every_random_case(where, test, method):
    routine = spec_from_dict(_pair_spec(where), base=DOMAIN)
    (part,) = [p for p in case_sets.plan(routine, exhaustive=False) if p.name == "random"]
    cases = list(part.cases)
    assert part.count == len(cases) == 1000 and all(test(a, b) for a, b in cases)
    assert part.draw.inside and part.draw.share < 0.01 and part.draw.method == method


def test_the_box_is_narrowed_from_the_comparisons():
    routine = spec_from_dict(_pair_spec("a + b == 300"), base=DOMAIN)
    draw = case_sets.domain_draw(routine, 0, 100)
    assert dict((n, (lo, hi)) for n, lo, hi in draw.ranges) == {"a": (45, 255), "b": (45, 255)}
    assert draw.candidates == 211 * 211  # the box's combinations, of which the 211 valid ones are drawn from


def _wide_doc(where: str, random: int = 500) -> dict:
    return {"program": {"file": "bcd_add.s", "entry": "bcd_add"},
            "inputs": {"a": {"at": "a_val", "size": 2, "table": False}, "b": {"at": "b_val", "size": 2, "table": False}},
            "outputs": {"sum": {"at": "sum", "size": 2, "table": False}, "carry": "C"},
            "reference": {"function": "refs.py:bcd_add"}, "cases": {"random": random, "where": where}}


def test_a_large_box_is_drawn_by_rejection_within_a_budget():
    # 2^32 combinations: too many to enumerate; 1 in 32 lies inside
    routine = spec_from_dict(_wide_doc("(a ^ b) & 31 == 0"), base=DOMAIN)
    (part,) = [p for p in case_sets.plan(routine, exhaustive=False) if p.name == "random"]
    cases = list(part.cases)
    assert len(cases) == part.count == 500 and all((a ^ b) & 31 == 0 for a, b in cases)
    assert part.draw.method == "rejection" and part.draw.candidates >= 500


def test_a_domain_too_rare_for_the_budget_gets_fewer_cases_and_says_so(capsys, monkeypatch):
    monkeypatch.setattr(case_sets, "DRAW_FLOOR", 1 << 16)
    monkeypatch.setattr(case_sets, "DRAW_BUDGET", 1)
    routine = spec_from_dict(_wide_doc("a & 0x3f == 0 and b & 0x3f == 0", random=2000), base=DOMAIN)
    (part,) = [p for p in case_sets.plan(routine, exhaustive=False) if p.name == "random"]
    cases = list(part.cases)
    assert 0 < len(cases) == part.count == part.draw.drawn < 2000  # 1 in 4,096: about 16 of 65,536 draws
    assert all(a & 0x3F == 0 and b & 0x3F == 0 for a, b in cases)
    assert part.draw.candidates == 1 << 16


def test_an_empty_domain_is_one_line():
    routine = spec_from_dict(_pair_spec("a + b > 600"), base=DOMAIN)
    with pytest.raises(InputError, match=r"cases.where: no value of a within its values lies inside the domain"):
        case_sets.plan(routine, exhaustive=False)


def test_a_domain_most_draws_meet_stays_uniform():
    # half the space: uniform draws (their outside cases show which conditions are needed)
    routine = spec_from_dict(_pair_spec("a < 128"), base=DOMAIN)
    (part,) = [p for p in case_sets.plan(routine, exhaustive=False) if p.name == "random"]
    assert not part.draw.inside and 0.45 < part.draw.share < 0.55
    assert any(a >= 128 for a, _ in part.cases)


@pytest.mark.parametrize("engine", ENGINES)
def test_per_part_values_on_both_engines(capsys, engine, tmp_path):
    routine = get(str(DOMAIN / "add8_parts.toml"))
    exhaustive = _cases(routine, "exhaustive")
    assert sorted(exhaustive) == [(a, b) for a in range(8) for b in range(8)]
    random = _cases(routine, "random")
    assert max(a for a, _ in random) > 200 and max(b for _, b in random) > 200  # full bytes
    code, record = _check(capsys, DOMAIN / "add8_parts.toml", "--engine", engine)
    (part,) = [p for p in record["coverage"] if p["part"] == "exhaustive"]
    assert code == 0 and part["cases"] == part["space"] == 64 and part["complete"]
    # a reference right only for a < 8: the exhaustive part passes, the random part (a up to 255) fails
    text = (DOMAIN / "add8_parts.toml").read_text().replace('file = "../entry/add_bcd.s"', f'file = "{ADD}"')
    spec = tmp_path / "small.toml"
    spec.write_text(text.replace('"refs.py:add8"', f'"{DOMAIN / "refs.py"}:add8_small_only"'))
    code, record = _check(capsys, spec, "--engine", engine)
    assert code == 1 and record["first_failure"]["inputs"]["a"] >= 8
    code, record = _check(capsys, spec, "--engine", engine, "--random", "0")
    assert code == 0 and record["cases"] == 64


def test_per_part_values_both_engines_agree(capsys):
    records = [_check(capsys, DOMAIN / "add8_parts.toml", "--engine", engine)[1] for engine in ENGINES]
    for key in ("cases", "min_inputs", "max_inputs", "coverage", "entry_dependence"):
        assert records[0][key] == records[1][key], key


@pytest.mark.parametrize("cases, message", [
    ({"exhaustive": {"a": "0..300"}}, "cases.exhaustive.a: 0..300 does not fit in A (0..255)"),
    ({"exhaustive": {"q": "0..3"}}, "cases.exhaustive.q: unknown input"),
    ({"random_values": {"b": "5..1"}}, "cases.random_values.b: empty range"),
    ({"random_values": {"b": 3}}, "cases.random_values.b: expected a range"),
    ({"random_inside": "yes"}, "cases.random_inside"),
])
def test_bad_part_values_are_one_line_naming_the_key(cases, message):
    doc = _pair_spec("a < 128")
    doc["cases"].update(cases)
    with pytest.raises(InputError) as caught:
        spec_from_dict(doc, base=DOMAIN)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_random_values_shape_the_random_part_only():
    doc = _pair_spec("a < 256", random=300, exhaustive={"a": [1, 2]}, random_values={"a": "200..210"})
    routine = spec_from_dict(doc, base=DOMAIN)
    assert {a for a, _ in _cases(routine, "exhaustive")} == {1, 2}
    assert {a for a, _ in _cases(routine, "random")} <= set(range(200, 211))
    assert routine.exhaustive_count() == 2  # only a is swept; b takes random values in that part


@pytest.mark.parametrize("engine", ENGINES)
def test_an_exhaustive_part_runs_only_its_combinations_inside_a_small_domain(capsys, engine, tmp_path):
    doc = _pair_spec("a + b == 300", random=0, exhaustive=["a", "b"])
    routine = spec_from_dict(doc, base=DOMAIN)
    cases = _cases(routine, "exhaustive")
    assert sorted(cases) == [(a, 300 - a) for a in range(45, 256)]  # the 211 of 65,536
    spec = tmp_path / "pairs.toml"
    spec.write_text(f'''[program]\nfile = "{ADD}"\nentry = "add_bcd"\n[inputs]\na = "A"\nb = "b_val"\n
[outputs]\nsum = "sum"\n[reference]\nfunction = "{DOMAIN / "refs.py"}:add8"\n[entry]\nd = 0\n
[cases]\nexhaustive = ["a", "b"]\nrandom = 0\nwhere = "a + b == 300"\n''')
    code, record = _check(capsys, spec, "--engine", engine)
    (part,) = record["coverage"]
    assert code == 0 and record["cases"] == 211 and record["outside_domain"] == 0
    assert part == {"part": "exhaustive", "cases": 211, "space": 65536, "inputs": ["a", "b"], "complete": True,
                    "inside": 211}
    main(["check", str(spec), "--engine", engine, "--jobs", "1"])
    assert "exhaustive over a, b: 211 of the 211 combinations inside the domain (of 65,536)" in capsys.readouterr().out


def test_an_exhaustive_part_over_a_large_domain_runs_every_combination():
    routine = spec_from_dict(_pair_spec("a < 128 and b >= 0", random=0, exhaustive=["a", "b"]), base=DOMAIN)
    (part,) = case_sets.plan(routine, exhaustive=False)
    assert part.count == 65536 and part.inside is None  # the outside half shows the condition is needed


def test_conditions_on_other_inputs_do_not_filter_the_sweep():
    # b is not swept: whether a case is inside depends on its random b, so every a runs
    routine = spec_from_dict(_pair_spec("a + b == 300", random=0, exhaustive=["a"]), base=DOMAIN)
    (part,) = case_sets.plan(routine, exhaustive=False)
    assert part.count == 256 and part.inside is None


@pytest.mark.parametrize("cases, message", [
    ({"random_inside": True, "random_generator": "refs.py:add8"}, "cases.random_inside: the random_generator draws"),
    ({"random_values": {"a": "0..3"}, "random_generator": "refs.py:add8"}, "cases.random_values: the random_generator"),
])
def test_part_keys_that_a_generator_would_ignore_are_refused(cases, message):
    doc = _pair_spec("a < 128")
    doc["cases"].update(cases)
    with pytest.raises(InputError, match=message):
        spec_from_dict(doc, base=DOMAIN)


def test_random_inside_needs_a_domain():
    doc = _pair_spec("a < 128")
    del doc["cases"]["where"]
    doc["cases"]["random_inside"] = True
    with pytest.raises(InputError, match="cases.random_inside: there is no domain"):
        spec_from_dict(doc, base=DOMAIN)
