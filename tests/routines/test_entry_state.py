"""Entry state as part of a spec's contract (issue 23 part 2): `[entry]` states what the caller
guarantees; everything else is arbitrary, and a case whose outputs or cycles change when it is all
ones or random is a failure naming what the routine depends on. The fixtures (tests/data/entry) are
routines with one hidden assumption each, their references written from what they are meant to do."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.cli import main
from retro.errors import InputError, RunError
from retro.routines.registry import get
from retro.routines.runner import RoutineRunner

ENTRY = Path(__file__).resolve().parents[1] / "data" / "entry"
ENGINES = ("scalar", "batch")


def _check(capsys, spec, *args) -> tuple[int, dict]:
    code = main(["check", str(spec), "--json", "--jobs", "1", *args])
    (record,) = json.loads(capsys.readouterr().out)
    return code, record


def _spec_with(tmp_path: Path, name: str, extra: str) -> Path:
    """A copy of a fixture's spec beside its files' absolute paths, with `extra` TOML appended."""
    text = (ENTRY / f"{name}.toml").read_text()
    text = text.replace(f'file = "{name.split("_stated")[0]}.s"', f'file = "{ENTRY / name.split("_stated")[0]}.s"')
    text = text.replace('"refs.py:', f'"{ENTRY / "refs.py"}:')
    path = tmp_path / f"{name}.toml"
    path.write_text(text + extra)
    return path


@pytest.mark.parametrize("engine", ENGINES)
def test_the_superoptimisers_overlap_test_needs_the_carry_clear(capsys, engine):
    code, record = _check(capsys, ENTRY / "overlap8.toml", "--exhaustive", "--engine", engine)
    entry = record["entry_dependence"]
    assert code == 1 and record["result_mismatches"] == 0  # with C = 0 on entry every answer is right
    assert entry["every"] == 1 and entry["cases"] == 65_536  # a small exhaustive space: every case again
    assert "needs C = 0 on entry: add it to the spec ([entry] c = 0), or clear it (CLC)" in entry["needs"]
    assert "needs D = 0 on entry: add it to the spec ([entry] d = 0), or clear it (CLD)" in entry["needs"]
    assert entry["changed"] > 0 and record["mismatches"] >= entry["changed"]
    assert "C" in entry["varied"] and "D" in entry["varied"] and "A" not in entry["varied"]  # A is input a


def test_the_overlap_tests_failure_is_real_at_207_215_with_the_carry_set():
    runner = RoutineRunner(get(str(ENTRY / "overlap8.toml")))
    assert runner.run((207, 215))[0] == (0,)  # 8 apart: no overlap, as |a - b| < 8 says
    carry = ({}, 1, 1)  # the carry set on entry, nothing else changed
    assert runner.run((207, 215), entry=carry)[0] == (1,)


@pytest.mark.parametrize("engine", ENGINES)
def test_stated_entry_conditions_are_kept_and_not_varied(capsys, engine, tmp_path):
    code, record = _check(capsys, ENTRY / "overlap8_stated.toml", "--engine", engine)
    entry = record["entry_dependence"]
    assert code == 0 and entry["changed"] == 0 and entry["needs"] == []
    assert entry["stated"] == {"C": 0, "D": 0} and "C" not in entry["varied"] and "D" not in entry["varied"]
    # a stated value is what every call starts with: C = 1 on entry makes the routine wrong
    code, record = _check(capsys, _spec_with(tmp_path, "overlap8", "\n[entry]\nc = 1\nd = 0\n"), "--engine", engine)
    assert code == 1 and record["result_mismatches"] > 0


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("name, need", [
    ("add_bcd", "needs D = 0 on entry: add it to the spec ([entry] d = 0), or clear it (CLD)"),
    ("index_x", "needs X = 0 on entry: add it to the spec ([entry] x = 0), or set it (LDX #0)"),
    ("scratch", "reads $00FB, which nothing sets before the call (baseline $00): declare it (an input, or a "
                "[memory] block), or write it before reading it"),
    ("room", None),  # the stack pointer: its value in the random variant depends on the seed
])
def test_each_hidden_assumption_is_named(capsys, engine, name, need):
    code, record = _check(capsys, ENTRY / f"{name}.toml", "--engine", engine)
    entry = record["entry_dependence"]
    assert code == 1 and record["result_mismatches"] == 0
    if need is None:
        (need,) = entry["needs"]
        assert need.startswith("depends on the stack pointer (S = $FD at its first instruction in the check, $")
        assert need.endswith("address the stack relative to S (TSX), never at fixed addresses in page 1")
    assert entry["needs"] == [need]
    assert entry["changed"] > 0


@pytest.mark.parametrize("name", ["overlap8", "add_bcd", "index_x", "scratch", "room"])
def test_both_engines_give_the_same_verdict(capsys, name):
    records = [_check(capsys, ENTRY / f"{name}.toml", "--engine", engine)[1] for engine in ENGINES]
    assert records[0]["entry_dependence"] == records[1]["entry_dependence"]
    assert records[0]["mismatches"] == records[1]["mismatches"]


def test_a_tasks_blocks_rerun_together_give_each_block_its_own_runs(capsys):
    """The array engines hold a task's blocks' rerun cases and run them at once (entry_runs.EntryBaseline):
    overlap8 --exhaustive with 2,000 random cases is two blocks of the batched core in one task, many of
    Machine's; every figure, the first changed case of each variant included, is Machine's."""
    records = [_check(capsys, ENTRY / "overlap8.toml", "--exhaustive", "--random", "2000", "--engine", engine)[1]
               for engine in ENGINES]
    assert records[0]["cases"] > 65_536 and records[0]["entry_dependence"]["changed"] > 0
    assert records[0]["entry_dependence"] == records[1]["entry_dependence"]


def test_the_text_report_names_the_dependence(capsys):
    main(["check", str(ENTRY / "index_x.toml"), "--jobs", "1"])
    text = capsys.readouterr().out
    assert "ENTRY 16 of 16 cases change" in text
    assert "ENTRY needs X = 0 on entry" in text and "ENTRY e.g. i=" in text


def test_a_routine_without_hidden_assumptions_says_so(capsys, tmp_path):
    code, record = _check(capsys, _spec_with(tmp_path, "index_x", "\n[entry]\nx = 0\n"))
    assert code == 0 and record["entry_dependence"]["changed"] == 0
    main(["check", str(tmp_path / "index_x.toml"), "--jobs", "1"])
    assert "entry state: 16 cases (every case) run again with A, Y, C, Z, I, D, V, N, S and untouched memory" in \
        capsys.readouterr().out


@pytest.mark.parametrize("extra, message", [
    ("c = 2", "entry.c: 2 is out of range 0..1"),
    ("x = 256", "entry.x: 256 is out of range 0..255"),
    ("q = 0", "entry.q: unknown register or flag"),
    ("A = 1", "entry.A: A is input a: every case sets it"),
    ("x = \"lots\"", "entry.x"),
])
def test_bad_entry_values_are_one_line_naming_the_key(tmp_path, extra, message):
    path = _spec_with(tmp_path, "overlap8", f"\n[entry]\n{extra}\n")
    with pytest.raises(InputError) as caught:
        get(str(path))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_which_cases_run_again():
    from retro.analysis.check.entry_runs import entry_every, rerun_positions

    assert entry_every(2_000, False, 65_536) == 1  # a small check: every case
    assert entry_every(65_536, True, 65_536) == 1  # an exhaustive check of a small space: every case
    assert entry_every(67_536, False, 65_536) == 34  # else about 2,000 of them
    assert entry_every(67_536, True, 65_536) == 34
    assert entry_every(100, True, 65_536, sweep=True) == 64  # a sweep's count is unknown: 1 in 64 at most
    # the same cases whatever the blocks: positions by the case's index in the check
    every = 7
    whole = rerun_positions(0, 100, every)
    pieces = [rerun_positions(first, 30, every) + first for first in range(0, 100, 30)]
    import numpy as np

    assert np.concatenate(pieces)[np.concatenate(pieces) < 100].tolist() == whole.tolist() == list(range(0, 100, 7))


# ---- the reruns on the compiled engine (entry_runs.rerun_engine) ------------------------------------

def _needs_numba():
    from retro.cpu.compiled import numba_problem

    if numba_problem() is not None:
        pytest.skip(numba_problem())


@pytest.mark.parametrize("name", ["overlap8", "add_bcd", "index_x", "scratch", "room"])
def test_compiled_reruns_give_the_batched_cores_verdict(capsys, monkeypatch, name):
    """With every rerun on the compiled engine (its per-lane registers, flags, memory and S of each
    variant), the entry-state figures are the batched core's, the first changed case of each variant
    and what it depends on included."""
    _needs_numba()
    from retro.analysis.check import entry_runs

    batched = _check(capsys, ENTRY / f"{name}.toml", "--exhaustive", "--engine", "batch")[1]
    monkeypatch.setattr(entry_runs, "ENTRY_COMPILED_RERUNS", 0)  # every check's reruns on the compiled engine
    monkeypatch.setattr(entry_runs, "CROSS_CHECKED", 0)  # none on the batched core: the compiled engine's alone
    compiled = _check(capsys, ENTRY / f"{name}.toml", "--exhaustive", "--engine", "compiled")[1]
    assert compiled["engine"] == "compiled"
    assert compiled["entry_dependence"] == batched["entry_dependence"] and batched["entry_dependence"]["changed"]
    assert compiled["mismatches"] == batched["mismatches"]


def test_compiled_reruns_are_cross_checked_on_the_batched_core(capsys, monkeypatch):
    """A compiled engine that counts one cycle too many when the entry state is varied is caught by the
    reruns' sample on the batched core: the check fails naming the case and both engines' answers."""
    _needs_numba()
    from retro.analysis.check import entry_runs
    from retro.routines import batch_runs

    run_compiled = batch_runs.run_compiled

    def one_cycle_more_when_varied(runner, columns, entry=None):
        outcome = run_compiled(runner, columns, entry)
        if entry is not None:
            outcome.cycles[-1] += 1
        return outcome

    monkeypatch.setattr(batch_runs, "run_compiled", one_cycle_more_when_varied)
    monkeypatch.setattr(entry_runs, "ENTRY_COMPILED_RERUNS", 0)
    monkeypatch.setattr(entry_runs, "CROSS_CHECKED", 1 << 20)  # every rerun compared: the changed one is last
    code = main(["check", str(ENTRY / "overlap8_stated.toml"), "--jobs", "1", "--engine", "compiled"])
    assert code == 1
    err = capsys.readouterr().err
    assert "the engines disagree on case" in err and "run with the entry state varied" in err


def test_which_engine_reruns():
    from retro.analysis.check.entry_runs import ENTRY_COMPILED_RERUNS, rerun_engine

    assert rerun_engine("batch", 10**9, True, 64) == "batch"  # the check's own engine first
    assert rerun_engine("compiled", 10**9, False, 0) == "batch"  # no reruns
    assert rerun_engine("compiled", 0, True, 64) == "batch"  # a sweep: its count unknown (measured: no gain)
    assert rerun_engine("compiled", ENTRY_COMPILED_RERUNS // 2, False, 1) == "compiled"  # two variants each
    assert rerun_engine("compiled", ENTRY_COMPILED_RERUNS // 2 - 1, False, 1) == "batch"


@pytest.mark.parametrize("engine", ["batch", "compiled"])
def test_blocks_rerun_together_keep_their_own_places(engine):
    """Several blocks' held reruns run and counted together (entry_runs.run_baselines, tally.entry_tally)
    give the figures of the blocks counted one by one: each case keeps its own index in the check (its
    block's first plus its place), which names the first changed case and seeds its random state."""
    if engine == "compiled":
        _needs_numba()
    from dataclasses import replace

    import numpy as np

    from retro.analysis.check.engines import run_on_batched_core, runner_for
    from retro.analysis.check.entry_runs import entry_baseline
    from retro.analysis.check.run import _variants
    from retro.analysis.check.tally import Tally, entry_tally

    spec = str(ENTRY / "index_x.toml")
    runner = runner_for(spec, 0)
    columns = [np.arange(16, dtype=np.int64)]
    block = run_on_batched_core(runner, columns)
    held = [entry_baseline(runner.routine, block.outputs, block.cycles, block.returned, columns, first, 1)
            for first in (0, 5_000, 9_000)]
    held[0] = replace(held[0], compared=np.zeros(16, dtype=bool))  # (outside the domain: its changes not counted)
    variants = _variants(spec, 0, None)
    together = entry_tally(variants, held, 0, engine)
    alone = Tally()
    for baseline in held:
        alone.merge(entry_tally(variants, [baseline], 0, engine))
    assert together.entry_cases == alone.entry_cases == 32 and together.entry_changed == alone.entry_changed == 32
    assert {v: f.index for v, f in together.entry_first.items()} == {"ones": 5_000, "random": 5_000}
    assert together.entry_first == alone.entry_first


def test_a_long_sweeps_larger_tasks_cross_check_as_many_reruns():
    """Tasks of a long sweep on the compiled engine are LONG_SWEEP_FACTOR times larger; their reruns are
    cross-checked on the batched core as much as the smaller tasks' were: CROSS_CHECKED for each
    CROSS_CHECKED_BLOCKS blocks held, so a compiled engine wrong on a later rerun is still caught."""
    _needs_numba()
    import numpy as np

    from retro.analysis.check import entry_runs
    from retro.analysis.check.engines import run_on_batched_core, runner_for
    from retro.analysis.check.entry_runs import CROSS_CHECKED, CROSS_CHECKED_BLOCKS, entry_baseline
    from retro.analysis.check.run import (COMPILED_TASK_FACTOR, LONG_SWEEP_CALLS, LONG_SWEEP_FACTOR, TASK_BLOCKS,
                                          Sweep, _variants)
    from retro.analysis.check.tally import entry_tally
    from retro.routines import batch_runs

    spec = str(ENTRY / "index_x.toml")
    sweep = Sweep(spec, 0, True, None, 0, "compiled")
    assert sweep.task_cases(LONG_SWEEP_CALLS - 1) == TASK_BLOCKS * COMPILED_TASK_FACTOR * sweep.block
    assert sweep.task_cases(LONG_SWEEP_CALLS) == LONG_SWEEP_FACTOR * sweep.task_cases(LONG_SWEEP_CALLS - 1)
    assert Sweep(spec, 0, True, None, 0, "batch").task_cases(LONG_SWEEP_CALLS) == TASK_BLOCKS * sweep.block

    runner = runner_for(spec, 0)
    columns = [np.arange(16, dtype=np.int64)]
    block = run_on_batched_core(runner, columns)
    held = [entry_baseline(runner.routine, block.outputs, block.cycles, block.returned, columns, 16 * k, 1)
            for k in range(2 * CROSS_CHECKED_BLOCKS)]  # 1,024 reruns a variant: 512 cross-checked
    wrong = CROSS_CHECKED + 40  # past the first CROSS_CHECKED
    run_compiled = batch_runs.run_compiled

    def one_cycle_more_on_a_later_rerun(runner, columns, entry=None):
        outcome = run_compiled(runner, columns, entry)
        if entry is not None and len(outcome.cycles) > wrong:
            outcome.cycles[wrong] += 1
        return outcome

    variants = _variants(spec, 0, None)
    entry_tally(variants, held, 0, "compiled")  # right: no error
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(batch_runs, "run_compiled", one_cycle_more_on_a_later_rerun)
        with pytest.raises(RunError, match=f"the engines disagree on case {wrong} run with the entry state varied"):
            entry_tally(variants, held, 0, "compiled")
        patch.setattr(entry_runs, "CROSS_CHECKED_BLOCKS", 1 << 20)  # (one task's worth, whatever its size)
        entry_tally(variants, held, 0, "compiled")  # not caught
