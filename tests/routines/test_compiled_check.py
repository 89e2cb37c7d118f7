"""`retro check --engine compiled`: the same JSON record as the batched core (and so as Machine, which
tests/routines/test_batch_check.py holds the batched core to) on every built-in and user fixture spec,
the engine and its reason in the report; a routine the compiled engine refuses runs on the batched core
and the report says why; a scene keeps Machine."""

from __future__ import annotations

import json

import pytest

from retro.analysis.check import engines
from retro.cli import main
from retro.cpu import compiled
from retro.cpu.compiled import numba_problem
from retro.routines.registry import builtin_names

from test_batch_check import SPECS, USER_SPECS  # noqa: E402 (pytest puts this folder on sys.path)

needs_numba = pytest.mark.skipif(numba_problem() is not None, reason=f"{numba_problem()}")
ENGINE_FIELDS = {"engine", "engine_agreement", "engine_reason", "compile_seconds", "compiled_fallbacks",
                 "code_coverage"}  # the compiled engine counts no code coverage (its report says so)


def check_json(capsys, *args) -> tuple[int, list[dict]]:
    code = main(["check", *args, "--json", "--jobs", "1"])
    return code, json.loads(capsys.readouterr().out)


def without_engine(record: dict) -> dict:
    return {k: v for k, v in record.items() if k not in ENGINE_FIELDS}


# Every user fixture spec (USER_SPECS and more), among them one with stated facts that its code
# contradicts ([facts]: Machine and the batched core stop the call; the compiled engine leaves such a
# spec to the batched core) and self-modifying code patched on one path only (smc/smc_some.toml).
FACTS_BROKEN = str(SPECS / "facts" / "lookup_broken.toml")
FIXTURE_SPECS = sorted(str(p) for p in SPECS.rglob("*.toml"))


def test_the_fixture_specs_include_the_batched_tests_ones():
    names = set(FIXTURE_SPECS)
    assert set(USER_SPECS) <= names and FACTS_BROKEN in names and len(names) > len(USER_SPECS)


@needs_numba
@pytest.mark.parametrize("spec", builtin_names() + FIXTURE_SPECS)
def test_every_spec_gives_the_same_record_on_all_three_engines(spec, capsys):
    """Machine, the batched core and the compiled engine: the same exit code and JSON record, the
    engine fields aside (and code coverage, which the compiled engine does not count)."""
    # (no search: it is steered by the code coverage)
    common = ("--random", "400", "--no-search")
    code_s, (scalar,) = check_json(capsys, spec, "--engine", "scalar", *common)
    code_b, (batched,) = check_json(capsys, spec, "--engine", "batch", *common)
    code_c, (compiled,) = check_json(capsys, spec, "--engine", "compiled", *common)
    assert (scalar["engine"], batched["engine"]) == ("scalar", "batch")
    assert code_s == code_b == code_c
    assert without_engine(scalar) == without_engine(batched) == without_engine(compiled)
    assert scalar.get("code_coverage") == batched.get("code_coverage")  # counted by these two only
    if compiled["engine"] == "compiled":
        assert compiled["engine_reason"] == "--engine compiled" and compiled["compile_seconds"] >= 0
        agreement = compiled["engine_agreement"]
        assert agreement["cases"] > 0 and agreement["mismatches"] == 0
    else:  # refused: the batched core ran, and the report says why
        assert compiled["engine"] == "batch" and compiled["engine_reason"].startswith(
            "the compiled engine does not take it: ")


@needs_numba
def test_self_modifying_code_that_patches_operands_runs_compiled(capsys):
    """pixel patches the high bytes of two table reads: compiled, the same record as the batched core."""
    common = ("--random", "300", "--no-search")
    code_b, (batched,) = check_json(capsys, "pixel", "--engine", "batch", *common)
    code_c, (compiled,) = check_json(capsys, "pixel", "--engine", "compiled", *common)
    assert code_b == code_c == 0 and compiled["engine"] == "compiled" and not compiled["compiled_fallbacks"]
    assert without_engine(batched) == without_engine(compiled)


@needs_numba
def test_auto_with_enough_cases_runs_pixel_compiled_with_the_batched_cores_record(capsys, monkeypatch):
    """auto picks the compiled engine above its threshold (lowered here below the check's work; 20,000
    cases: auto's threshold for an array engine): pixel's record is the batched core's."""
    monkeypatch.setattr(engines, "AUTO_COMPILED_CYCLES", 1)
    common = ("--random", "20000", "--no-search")
    code_b, (batched,) = check_json(capsys, "pixel", "--engine", "batch", *common)
    code_a, (auto,) = check_json(capsys, "pixel", "--engine", "auto", *common)
    assert code_b == code_a == 0 and auto["engine"] == "compiled" and auto["engine_reason"].startswith("auto: ")
    assert without_engine(batched) == without_engine(auto)


@needs_numba
def test_a_store_into_an_opcode_runs_on_the_batched_core_and_says_why(capsys, tmp_path):
    (tmp_path / "smc_opcode.s").write_text(
        "        .org $c000\n"
        "smc_opcode:\n"
        "        lda #$a9\n"
        "        sta patch      ; the opcode of the next instruction (the same LDA #)\n"
        "patch:  lda #0\n"
        "        rts\n")
    (tmp_path / "refs.py").write_text("def zero(x):\n    return 0\n")
    (tmp_path / "smc_opcode.toml").write_text(
        'summary = "a store into an opcode"\n[program]\nfile = "smc_opcode.s"\nentry = "smc_opcode"\n'
        '[inputs]\nx = { at = "X", values = "0..3" }\n[outputs]\nbyte = "A"\n'
        '[reference]\nfunction = "refs.py:zero"\n[cases]\nexhaustive = ["x"]\n[cycles]\nstatic = false\n')
    spec = str(tmp_path / "smc_opcode.toml")
    code, (record,) = check_json(capsys, spec, "--engine", "compiled")
    assert code == 0 and record["engine"] == "batch"
    assert record["engine_reason"] == ("the compiled engine does not take it: self-modifying code: the instruction "
                                       "at $C002 writes $C005, an opcode byte of the routine's code")
    main(["check", spec, "--engine", "compiled", "--jobs", "1"])
    assert "engine: batch (the compiled engine does not take it: self-modifying code" in capsys.readouterr().out


def test_without_numba_auto_runs_the_batched_core_and_says_so_once(monkeypatch, capsys):
    monkeypatch.setattr(compiled, "numba_problem", lambda: "numba cannot be imported (ImportError: no numba)")
    monkeypatch.setattr(engines, "_SAID", set())
    assert engines.array_engine("auto", None) == ("batch", "numba cannot be imported (ImportError: no numba)")
    assert engines.array_engine("auto", 10 ** 9, 10 ** 11)[0] == "batch"
    assert engines.array_engine("compiled", 5)[0] == "batch"
    assert capsys.readouterr().err.count("the compiled engine is off: numba cannot be imported") == 1
    assert engines.array_engine("auto", 30_000, 900_000) == ("batch", "auto: 30,000 planned calls, about 1 M cycles "
                                                                      "(the compiled engine from 127 M)")


@needs_numba
def test_auto_takes_the_compiled_engine_for_a_sweep_or_calls_whose_work_pays_for_its_start():
    """The rule's crossover, measured (benchmarks/compiled_speed.py --auto: the batched core 3.9 ns a cycle, the
    compiled engine 0.35, 0.45 CPU-s to start): 126,760,563 cycles; a call's cycles the geometric mean of the
    static bounds. Both sides of it, and where the built-ins' --exhaustive checks fall."""
    assert engines.AUTO_COMPILED_CYCLES == 126_760_563
    assert engines.compiled_pays(126_760_563) and not engines.compiled_pays(126_760_562)
    assert engines.array_engine("auto", None) == ("compiled", "auto: a sweep")
    assert engines.array_engine("auto", 1_000, 126_760_563) == ("compiled", "auto: 1,000 planned calls, about 127 M cycles")
    assert engines.array_engine("auto", 20_000_000, 126_000_000)[0] == "batch"  # many calls, little work each
    assert engines.array_engine("batch", None) == ("batch", "--engine batch")
    assert engines.expected_cycles(52, 26_800) == pytest.approx(1180.5, abs=0.1)
    assert engines.expected_cycles(0, 40) == pytest.approx(6.32, abs=0.01)  # (a zero bound counts as one cycle)


@needs_numba
@pytest.mark.parametrize("name, engine", [("tile_box", "compiled"), ("tile", "batch"), ("aabb_sprite", "batch"),
                                          ("circle", "compiled")])
def test_auto_on_the_built_ins_exhaustive_checks(name, engine):
    """tile_box's 234,472 long calls (a loop: static bounds 52 and 26,800 cycles, 277 M cycles planned) take the
    compiled engine; tile's 231,192 short ones (15-44 cycles, 6 M) and aabb_sprite's (17 M) the batched core."""
    from retro.analysis.check.run import _planned, _static
    from retro.routines.registry import spec_path

    plan = _planned(str(spec_path(name)), True, None, None, 1 << 20)
    runner = engines.runner_for(plan.spec, plan.seed)
    cycles = engines.planned_cycles(runner, plan.parts, _static(plan, runner))
    assert engines.array_engine("auto", plan.calls, cycles)[0] == engine


def test_without_static_bounds_auto_takes_a_call_s_cycles_from_machine(tmp_path):
    """A spec that turns the static analysis off: the first AUTO_PROBE_CASES cases of each part run on Machine."""
    from retro.analysis.check.run import _planned
    from retro.routines.registry import spec_path

    plan = _planned(str(spec_path("mul8")), True, None, None, 1 << 20)
    runner = engines.runner_for(plan.spec, plan.seed)
    measured = engines.planned_cycles(runner, plan.parts, None)
    assert [p.count for p in plan.parts] == [64, 65_536, 100_000]
    assert 44 * plan.calls <= measured <= 48 * plan.calls  # mul8 takes 44-48 cycles a call
    assert measured != round(46 * plan.calls)  # (measured, not the bounds' mean)


def test_when_numba_fails_to_import_auto_runs_the_batched_core_and_says_so_once():
    """The import itself fails (sys.modules["numba"] = None makes `import numba` raise ImportError), in a
    fresh process: the engine modules still import, auto picks the batched core, one line on stderr."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    script = ("import sys\nsys.modules['numba'] = None\n"
              "from retro.analysis.check import engines\n"
              "print(engines.array_engine('auto', None))\nprint(engines.array_engine('auto', 10 ** 9, 10 ** 11))\n")
    root = str(Path(__file__).resolve().parents[2])
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": root})
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("('batch', 'numba cannot be imported (ModuleNotFoundError") == 2
    assert done.stderr.count("the compiled engine is off: numba cannot be imported") == 1


@needs_numba
def test_stated_facts_leave_the_routine_to_the_batched_core_and_say_why(capsys):
    code, (record,) = check_json(capsys, FACTS_BROKEN, "--engine", "compiled", "--random", "50")
    assert code == 1 and record["engine"] == "batch"
    assert record["engine_reason"] == ("the compiled engine does not take it: the spec states facts ([facts]), "
                                       "which it does not hold against the calls")


@needs_numba
def test_a_compiled_run_starts_from_the_call_image_as_it_is_now():
    """run_compiled keeps the call image with its return trap pushed from block to block
    (batch_runs._entered_image); a call image changed since (reset_memory: the entry-state runs) is
    the one the next block runs from, as on the batched core."""
    import numpy as np

    from retro.routines import cases as case_sets
    from retro.routines.registry import get
    from retro.routines.runner import RoutineRunner

    routine = get("tile")
    runner = RoutineRunner(routine, routine.seed)
    cases = [(x & 0xFF, x >> 8, y) for x in range(24, 344, 7) for y in range(50, 250, 9)]
    columns = case_sets.cases_to_columns(routine, cases)
    before = runner.run_compiled(columns).outputs[0].copy()
    props = next(block for block in routine.memory if block.name == "props").address
    image = bytearray(runner.call_image)
    image[props:props + 256] = bytes((b + 1) & 0xFF for b in image[props:props + 256])
    runner.reset_memory(bytes(image))
    after = runner.run_compiled(columns).outputs[0]
    assert np.array_equal(after, runner.run_batch(columns).outputs[0])
    assert np.count_nonzero(after != before) > len(cases) // 2
