"""A scene no longer forces Machine: a routine that touches no chip register runs on the batched core
with each lane stalled by the VIC-II as Machine stalls it (Bad Lines, sprite DMA) from the start line
and cycle; one that might touch a chip, or might be interrupted, stays on Machine, and the report
says which engine ran and why."""

from __future__ import annotations

import numpy as np
import pytest

from retro.analysis.check.engines import SceneStart, run_on_batched_core, run_on_machine
from retro.commands.check import check_record, format_check
from retro.analysis.check import run_checks
from retro.routines import cases as case_sets
from retro.routines.runner import RasterStart, RoutineRunner
from retro.routines.spec import load_spec
from retro.paths import ASM_DIR, EXAMPLES_DIR

SCENE = str(EXAMPLES_DIR / "vic_two_balls.toml")  # text on (Bad Lines on lines $33, $3B, ...), sprites 0-3


def both_engines(spec: str, line: int, cycle: int, n: int = 3000):
    routine = load_spec(ASM_DIR / f"{spec}.toml")
    start = SceneStart(SCENE, line, cycle).raster_start()
    runner = RoutineRunner(routine, 0, start)
    columns = next(case_sets.batches(case_sets.plan(routine, exhaustive=False, seed=0, random=n), n))
    cases = case_sets.columns_to_cases(columns)
    return runner, run_on_machine(runner, cases), run_on_batched_core(runner, columns)


# on a Bad Line with sprite DMA, just before it, in the middle of its stolen cycles, and off it
@pytest.mark.parametrize("line, cycle", [(51, 1), (51, 9), (51, 30), (59, 50), (100, 55), (203, 3)])
def test_the_batched_core_stalls_every_lane_as_machine_does(line, cycle):
    runner, machine, batch = both_engines("circle_r", line, cycle)
    assert runner.batchable
    assert machine.returned == batch.returned == len(machine.cycles)
    np.testing.assert_array_equal(batch.cycles, machine.cycles)
    np.testing.assert_array_equal(batch.stolen, machine.stolen)
    assert machine.stolen.max() > 0   # the start is where the VIC-II takes the bus: stalls were counted


@pytest.mark.parametrize("spec, why", [("mul8", "an indirect access"), ("pixel", "may rewrite the routine's own code"),
                                       ("tile", "an indirect access")])
def test_a_routine_that_might_reach_a_chip_stays_on_machine(spec, why):
    routine = load_spec(ASM_DIR / f"{spec}.toml")
    runner = RoutineRunner(routine, 0, SceneStart(SCENE, 100, 1).raster_start())
    assert not runner.batchable and why in runner.engine_reason


def test_the_report_says_which_engine_ran_and_why():
    start = SceneStart(SCENE, 51, 9)
    batch, scalar = (run_checks(["circle_r", "mul8"], start=start, engine=engine, jobs=1) for engine in ("auto", "scalar"))
    assert batch[0].engine == "batch" and batch[1].engine == "scalar"
    assert check_record(batch[0])["engine_reason"].startswith("the routine touches no chip register")
    assert "engine with the scene: the batched core" in "\n".join(format_check(batch[0]))
    assert "indirect access" in "\n".join(format_check(batch[1]))
    # both engines agree on the whole check: cycles, stalls, where the slowest case ends
    for key in ("min", "max", "mean", "min_inputs", "max_inputs", "raster", "mismatches"):
        assert check_record(batch[0])[key] == check_record(scalar[0])[key], key
    assert check_record(batch[0])["engine_agreement"]["mismatches"] == 0
