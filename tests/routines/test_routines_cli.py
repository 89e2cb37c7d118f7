"""`retro check` and `retro cycles`: fields, exit codes, errors."""

from __future__ import annotations

import json

from retro.analysis.cost import COST_FIELDS
from retro.cli import main
from retro.routines.registry import ROUTINES, get


def test_cycles_json_has_exactly_the_fields(capsys):
    assert main(["cycles", "aabb8", "mul8", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [row["routine"] for row in rows] == ["aabb8", "mul8"]
    for row in rows:
        assert tuple(row) == COST_FIELDS
        assert row["mismatches"] == 0
        assert row["static_min"] <= row["min"] <= row["mean"] <= row["max"] <= row["static_max"]
    assert rows[1]["table_bytes"] == 4 * 512  # four 512-byte quarter-square tables


def test_check_json_and_exit_zero(capsys):
    assert main(["check", "tile", "--json", "--random", "100"]) == 0
    (record,) = json.loads(capsys.readouterr().out)
    assert record["routine"] == "tile" and record["mismatches"] == 0 and record["cases"] > 100


def test_check_exits_1_on_a_mismatch_and_prints_the_inputs(monkeypatch, capsys):
    routine = get("mul8")
    monkeypatch.setitem(ROUTINES, "mul8", type(routine)(**{**routine.__dict__, "reference": lambda c, w: c[0] * c[1] + 1}))
    assert main(["check", "mul8", "--random", "0", "--jobs", "1"]) == 1
    assert "A=0, Y=0" in capsys.readouterr().out


def test_unknown_routine_is_one_line_exit_2(capsys):
    assert main(["check", "aabb9"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown routine 'aabb9'" in err
    assert main(["cycles", "nope", "--json"]) == 2


def test_a_routine_named_twice_is_reported_once(capsys):
    assert main(["cycles", "aabb8", "aabb8", "--json"]) == 0
    assert [row["routine"] for row in json.loads(capsys.readouterr().out)] == ["aabb8"]
