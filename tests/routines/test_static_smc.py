"""Static bounds of self-modifying code: one bound per spec, whatever the engine and the jobs.

The fixtures (tests/data/specs/smc/) count their cycles by hand in their headers. Before the
analysis read the code as loaded, smc_mul got static 44-48 on one engine and a false failure
("measured maximum 48 is above the static worst case 44") on another: it read the operand bytes the
last case had left in memory."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.cli import main

SMC = Path(__file__).resolve().parents[1] / "data" / "specs" / "smc"


def _record(capsys, spec: str, *args: str) -> tuple[int, dict]:
    code = main(["check", str(SMC / spec), "--json", *args])
    (record,) = json.loads(capsys.readouterr().out)
    return code, record


@pytest.mark.parametrize("engine", ["scalar", "batch"])
@pytest.mark.parametrize("jobs", ["1", "2"])
def test_self_modifying_multiply_gets_one_bound_on_every_engine_and_jobs(capsys, engine, jobs):
    code, record = _record(capsys, "smc_mul.toml", "--engine", engine, "--jobs", jobs)
    # 44 + one cycle per crossing read; a + b >= 256 and b > a both happen (a = 128, b = 255): 48
    assert code == 0 and record["bounds_violations"] == []
    assert (record["static_min"], record["static_max"]) == (44, 48)
    assert (record["min"], record["max"]) == (44, 48) and record["worst_reached"]
    # the four patched reads are named (sum_lo at $C00F: four 3-byte stores, EOR # (2) and SEC (1) before it)
    assert len(record["static_modified"]) == 4
    assert record["static_modified"][0] == ("LDA at $C00F (sum_lo): its operand is written by the store at $C000; "
                                            "bounded from the values stored")


def test_values_of_the_stored_byte_decide_the_crossing(capsys):
    # a, b < 128: the sum reads (low byte a, index b) never cross (a + b <= 254); the difference
    # reads (low byte 255 - a >= 128) cross when b > a: 44-46, exactly what the cases measure
    code, record = _record(capsys, "smc_mul_small.toml", "--jobs", "1")
    assert code == 0 and (record["static_min"], record["static_max"]) == (44, 46) == (record["min"], record["max"])


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_page_stored_into_an_operand_keeps_its_low_byte(capsys, engine):
    # the table's page varies with A; the operand's low byte stays $80 and Y < $80: never a crossing
    code, record = _record(capsys, "smc_page.toml", "--engine", engine, "--jobs", "1")
    assert code == 0 and (record["static_min"], record["static_max"]) == (18, 18) == (record["min"], record["max"])


def test_the_bounds_come_from_the_code_as_loaded_not_from_memory_a_case_left():
    # smc_some patches its operand on one path only; after a carry-set call the runner's memory holds
    # $FF there (Machine's memory persists), but the carry-clear path still starts from the byte as loaded
    # ($00 + X = 1: no crossing, 13 cycles); the other path 19 (header of smc_some.s)
    from retro.analysis.check.verdicts import static_bounds
    from retro.routines.registry import get
    from retro.routines.runner import RoutineRunner

    routine = get(str(SMC / "smc_some.toml"))
    runner = RoutineRunner(routine)
    assert runner.run((1, 1)) == ((0,), 19)
    assert runner.machine.memory[runner.entry + 8] == 0xFF  # the patched operand, left in memory
    bounds = static_bounds(routine, runner)
    assert (bounds.best, bounds.worst) == (13, 19)


def test_every_call_on_machine_starts_from_the_code_as_loaded():
    # smc_some's carry-set path leaves $FF in its read's operand; the next call (carry clear) must not
    # see it (LDA $C2FF,X would cross a page: 14 cycles): each call starts from the code as every lane
    # of the array engines does, whatever case ran before it (13 cycles: the header of smc_some.s)
    from retro.routines.registry import get
    from retro.routines.runner import RoutineRunner

    runner = RoutineRunner(get(str(SMC / "smc_some.toml")))
    assert [runner.run(case) for case in [(1, 1), (0, 1), (1, 1), (0, 1)]] == [((0,), 19), ((0,), 13)] * 2
