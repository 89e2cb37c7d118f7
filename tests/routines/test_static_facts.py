"""The static bounds beside a scene (CPU cycles, said so) and the facts a spec states ([facts])."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.cli import main

SCENE = "examples/vic_two_balls.toml"


def test_with_a_scene_the_static_bounds_say_they_count_cpu_cycles_only(capsys):
    assert main(["check", "--scene", SCENE, "aabb8", "--jobs", "1", "--json"]) == 0
    (record,) = json.loads(capsys.readouterr().out)
    # measured with stalls above the static worst, CPU-only within it: compared like with like
    assert record["max"] > record["static_max"] == record["cpu_max"] == 34
    assert record["cpu_min"] == record["static_min"] == 20 and record["bounds_violations"] == []
    assert main(["check", "--scene", SCENE, "aabb8", "--jobs", "1"]) == 0
    headline = capsys.readouterr().out.splitlines()[0]
    assert "CPU 20-34 without the cycles the chip stole, static 20-34 CPU cycles (stolen cycles not included)" in headline


FACTS = Path(__file__).resolve().parents[1] / "data" / "specs" / "facts"


def _record(capsys, spec: str, engine: str = "scalar") -> tuple[int, dict]:
    code = main(["check", str(FACTS / spec), "--json", "--jobs", "1", "--engine", engine])
    (record,) = json.loads(capsys.readouterr().out)
    return code, record


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_stated_branch_or_register_fact_tightens_the_bounds_and_holds(capsys, engine):
    # lookup.s's header: 12 when BMI falls through, 17 when taken; the levels come from a generator
    # (unknown to the analysis), so without a fact both ways count
    code, record = _record(capsys, "lookup_plain.toml", engine)
    assert code == 0 and (record["static_min"], record["static_max"]) == (12, 17) and not record["worst_reached"]
    for spec in ("lookup_branch.toml", "lookup_register.toml"):  # "not taken", or A in 0..127 (N clear)
        code, record = _record(capsys, spec, engine)
        assert code == 0 and (record["static_min"], record["static_max"]) == (12, 12) == (record["min"], record["max"])


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_case_that_contradicts_a_fact_fails_naming_it(capsys, engine):
    code, record = _record(capsys, "lookup_broken.toml", engine)
    assert code == 1 and record["run_errors"] == 1
    failure = record["first_failure"]
    assert failure["inputs"] == {"x": 0}
    assert "contradicts facts.check (branch not taken) at $C003 (A=200" in failure["message"]


def test_the_batched_core_stops_the_lanes_that_contradict_a_fact():
    import numpy as np

    from retro.cpu.batch import LaneError
    from retro.routines.registry import get
    from retro.routines.runner import RoutineRunner

    runner = RoutineRunner(get(str(FACTS / "lookup_broken.toml")))
    outcome = runner.run_batch([np.arange(16)])
    assert (outcome.error == LaneError.FACT).all()
    fine = RoutineRunner(get(str(FACTS / "lookup_branch.toml"))).run_batch([np.arange(16)])
    assert (fine.error == 0).all() and (fine.cycles == 12).all()


@pytest.mark.parametrize("facts, message", [
    ('check = "sometimes"', 'facts.check: expected "taken" or "not taken", got \'sometimes\''),
    ('lookup = "taken"', "facts.lookup: the instruction at $C000 is LDA, not a conditional branch"),
    ('nowhere = "taken"', "facts.nowhere: unknown label 'nowhere'"),
    ('check = { x = "0..300" }', "facts.check.x: 0..300 does not fit a register (0..255)"),
    ('check = { c = 2 }', "facts.check.c: "),
    ('check = { q = 1 }', "facts.check.q: unknown key"),
    ('check = 5', 'facts.check: expected "taken", "not taken" or a table'),
    ('"$0400" = "taken"', "facts.$0400: $0400 is outside the program"),
    ('check = {}', "facts.check: states nothing"),
])
def test_a_bad_fact_is_one_line_naming_its_key(tmp_path, capsys, facts, message):
    text = (FACTS / "lookup_branch.toml").read_text().split("[facts]")[0] + "[facts]\n" + facts + "\n"
    for name in ("lookup.s", "refs.py"):
        (tmp_path / name).write_text((FACTS / name).read_text())
    (tmp_path / "spec.toml").write_text(text)
    assert main(["check", str(tmp_path / "spec.toml"), "--jobs", "1"]) == 2
    error = capsys.readouterr().err.strip()
    assert message in error and len(error.splitlines()) == 1, error
