"""The example's own tests: run with `pytest examples/boxhit` (CI runs them with the project's tests)."""

from pathlib import Path

import pytest

from retro.testing import RoutineFailed, assert_routine, check, spec_from_dict

HERE = Path(__file__).parent
SPEC = HERE / "boxhit.toml"


def test_boxhit_matches_its_reference_within_budget():
    report = assert_routine(SPEC, random=500)
    assert report.totals.cases > 65_536  # the exhaustive pairs of left edges, then random cases
    # every condition of the domain is needed: outside it the routine answers wrongly
    assert all(report.totals.constraint_wrong.get(c.text, 0) > 0 for c in report.routine.domain)
    assert report.static.worst <= 80


def test_a_tighter_budget_fails_with_the_report():
    spec = spec_from_dict({
        "program": {"file": "boxhit.prg", "symbols": "boxhit.sym", "entry": "boxhit"},
        "inputs": {name: f"box{box}_{axis}" for name, box, axis in
                   (("ax", "a", "x"), ("ay", "a", "y"), ("aw", "a", "w"), ("ah", "a", "h"),
                    ("bx", "b", "x"), ("by", "b", "y"), ("bw", "b", "w"), ("bh", "b", "h"))},
        "outputs": {"hit": "C"},
        "reference": {"function": "boxhit_ref.py:boxhit"},
        "cases": {"random": 300, "where": "ax + aw <= 255 and bx + bw <= 255 and ay + ah <= 255 and by + bh <= 255"},
        "cycles": {"max": 40},
    }, base=HERE)
    with pytest.raises(RoutineFailed, match="over the budget of 40"):
        assert_routine(spec)
    assert check(spec).budget_violations
