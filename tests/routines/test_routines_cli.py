"""`retro check` and `retro cycles` on the built-in routines: fields, exit codes, errors."""

from __future__ import annotations

import json
import shutil

import pytest

from retro.commands.cycles import COST_FIELDS
from retro.cli import main
from retro.paths import ASM_DIR


def test_cycles_json_has_exactly_the_fields(capsys):
    assert main(["cycles", "aabb8", "mul8", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [row["routine"] for row in rows] == ["aabb8", "mul8"]
    for row in rows:
        assert tuple(row) == COST_FIELDS
        assert row["mismatches"] == 0
        assert row["static_min"] <= row["min"] <= row["mean"] <= row["max"] <= row["static_max"]
    assert rows[1]["table_bytes"] == 4 * 512  # four 512-byte quarter-square tables
    # mul8's cost is 44 plus one cycle per table read that crosses a page (asm/mul8.s header):
    # a = 0, b = 0 crosses none; b > a and a + b >= 256 cross all four.
    assert rows[1]["min"] == 44 and rows[1]["min_inputs"] == {"a": 0, "b": 0}
    assert rows[1]["max"] == 48 and rows[1]["max_inputs"]["b"] > rows[1]["max_inputs"]["a"]
    assert rows[1]["max_inputs"]["a"] + rows[1]["max_inputs"]["b"] >= 256
    assert rows[1]["budget"] is None
    pal = rows[1]["raster"]["c64_pal"]
    assert pal["cycles_per_line"] == 63 and pal["frame_cycles"] == 63 * 312
    assert pal["max_lines"] == round(48 / 63, 3)
    assert rows[1]["raster"]["c64_ntsc"]["max_lines"] == round(48 / 65, 3)


def test_check_json_and_exit_zero(capsys):
    assert main(["check", "tile", "--json", "--random", "100"]) == 0
    (record,) = json.loads(capsys.readouterr().out)
    assert record["routine"] == "tile" and record["mismatches"] == 0 and record["cases"] > 100
    assert record["first_failure"] is None
    assert [part["part"] for part in record["coverage"]] == ["boundary", "random"]


def test_check_exits_1_on_a_mismatch_and_prints_the_inputs(tmp_path, capsys):
    # mul8's own spec with a reference that is off by one: every case is a mismatch
    for name in ("mul8.s", "mul8.toml"):
        shutil.copy(ASM_DIR / name, tmp_path / name)
    spec = tmp_path / "mul8.toml"
    spec.write_text(spec.read_text().replace('function = "retro.routines.reference:mul8"',
                                             'function = "wrong.py:mul8"'))
    (tmp_path / "wrong.py").write_text("def mul8(a, b):\n    return a * b + 1\n")
    assert main(["check", str(spec), "--random", "0", "--jobs", "1"]) == 1
    out = capsys.readouterr().out
    assert "a=0, b=0): returned product=0, reference product=1" in out
    assert "first failing case: a=0, b=0" in out
    assert "$C000  STA $10" in out  # the trace of the failing case, from the routine's first instruction


def test_unknown_routine_is_one_line_exit_2(capsys):
    assert main(["check", "aabb9"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown routine 'aabb9'" in err
    assert main(["cycles", "nope", "--json"]) == 2


def test_a_routine_named_twice_is_reported_once(capsys):
    assert main(["cycles", "aabb8", "aabb8", "--json"]) == 0
    assert [row["routine"] for row in json.loads(capsys.readouterr().out)] == ["aabb8"]


def test_abbreviated_options_are_refused(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["check", "mul8", "--exhaustiv"])
    assert stop.value.code == 2
    assert "unrecognized arguments" in capsys.readouterr().err
