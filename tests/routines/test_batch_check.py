"""`retro check` on the batched core: the same verdict as Machine on every spec, field for field,
engine disagreements caught, run errors reported as Machine reports them, bad column blocks and
array references refused in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from retro.analysis.check import check_routine
from retro.analysis.check import engines as check_module
from retro.cli import main
from retro.cpu import batch, lane_memory
from retro.errors import InputError
from retro.routines import cases as case_sets
from retro.routines import batch_runs
from retro.routines.registry import builtin_names, get
from retro.routines.runner import RoutineRunner

SPECS = Path(__file__).resolve().parents[1] / "data" / "specs"
USER_SPECS = sorted(str(p) for p in SPECS.glob("boxhit_*.toml")) + [str(SPECS / "scan" / "scan.toml"),
                                                                       str(SPECS / "wide" / "wide.toml")]
ENGINE_FIELDS = {"engine", "engine_agreement", "engine_reason", "compile_seconds", "compiled_fallbacks"}


def check_json(capsys, *args) -> tuple[int, list[dict]]:
    code = main(["check", *args, "--json", "--jobs", "1"])
    return code, json.loads(capsys.readouterr().out)


def without_engine(record: dict) -> dict:
    return {k: v for k, v in record.items() if k not in ENGINE_FIELDS}


@pytest.mark.parametrize("spec", builtin_names() + USER_SPECS)
def test_both_engines_give_the_same_check(spec, capsys):
    code_s, (scalar,) = check_json(capsys, spec, "--engine", "scalar", "--random", "400")
    code_b, (batched,) = check_json(capsys, spec, "--engine", "batch", "--random", "400")
    assert (scalar["engine"], batched["engine"]) == ("scalar", "batch")
    assert code_s == code_b
    assert without_engine(scalar) == without_engine(batched)
    agreement = batched["engine_agreement"]
    assert agreement["cases"] > 0 and agreement["mismatches"] == 0 and agreement["timing_model_mismatches"] == 0


def test_a_wrong_routine_fails_the_same_way_on_the_batched_core(capsys):
    code, (record,) = check_json(capsys, str(SPECS / "boxhit_acme_wrong.toml"), "--engine", "batch")
    assert code == 1 and record["result_mismatches"] > 0
    assert record["first_failure"]["kind"] == "result" and record["first_failure"]["trace"]


def test_an_engine_disagreement_is_a_mismatch(monkeypatch, capsys):
    """A batched core that charges CLC one cycle too many must be caught by Machine's agreement run."""
    clc = batch.HANDLERS[0x18]

    def slow_clc(g, pc, lo, hi):
        g.cycles += 1
        return clc(g, pc, lo, hi)
    monkeypatch.setitem(batch.HANDLERS, 0x18, slow_clc)
    monkeypatch.setattr(check_module, "_RUNNERS", {})
    code, (record,) = check_json(capsys, "aabb8", "--engine", "batch", "--random", "300")
    assert code == 1
    assert record["engine_agreement"]["mismatches"] > 0
    # the disagreements are mismatches in their own right (the extra cycle also breaks the static bound)
    assert record["mismatches"] == (record["result_mismatches"] + record["cycle_mismatches"] + record["run_errors"]
                                    + len(record["bounds_violations"]) + len(record["budget_violations"])
                                    + record["engine_agreement"]["mismatches"])
    assert record["first_failure"]["kind"] == "engine"
    assert "engines disagree" in record["first_failure"]["message"]


def _one_input_spec(tmp_path: Path, body: str, extra: str = "") -> str:
    (tmp_path / "r.s").write_text("        .org $c000\nentry:\n" + body)
    (tmp_path / "ref.py").write_text("def f(a):\n    return a\n")
    (tmp_path / "r.toml").write_text('[program]\nfile = "r.s"\nentry = "entry"\n[inputs]\na = "A"\n'
                                     '[outputs]\nr = "A"\n[reference]\nfunction = "ref.py:f"\n'
                                     '[cases]\nexhaustive = ["a"]\n' + extra)
    return str(tmp_path / "r.toml")


@pytest.mark.parametrize("body, extra, says", [
    ("        cmp #$c8\n        bne ok\n        brk\nok:     rts\n", "[cycles]\nstatic = false\n", "BRK"),
    ("        cmp #$c8\n        bne ok\nspin:   jmp spin\nok:     rts\n", "[cycles]\nlimit = 500\nstatic = false\n",
     "cycle budget of 500 cycles"),
    ("        cmp #$c8\n        bne ok\n        .byte $02\nok:     rts\n", "[cycles]\nstatic = false\n", "JAM"),
])
def test_a_call_that_does_not_return_stops_the_check_as_on_machine(tmp_path, capsys, body, extra, says):
    spec = _one_input_spec(tmp_path, body, extra)
    code_s, (scalar,) = check_json(capsys, spec, "--engine", "scalar")
    code_b, (batched,) = check_json(capsys, spec, "--engine", "batch")
    assert code_s == code_b == 1
    assert batched["run_errors"] == 1 and batched["first_failure"]["kind"] == "run"
    assert batched["first_failure"]["inputs"] == {"a": 0xC8}
    assert says in batched["first_failure"]["message"]
    assert batched["cases"] == scalar["cases"] == 0xC8 + 1  # the cases before it, and it
    assert without_engine(scalar) == without_engine(batched)


def test_with_a_scene_a_routine_reading_a_chip_register_runs_on_machine_only(tmp_path, capsys):
    (tmp_path / "screen.toml").write_text('chip = "vic-ii"\nvideo = "pal"\n[registers]\n"$d011" = 0x1b\n')
    spec = _one_input_spec(tmp_path, "        lda $d012\n        rts\n")
    code = main(["check", spec, "--scene", str(tmp_path / "screen.toml"), "--at-line", "48", "--engine", "batch"])
    err = capsys.readouterr().err
    assert code == 2 and "--engine batch" in err and "reaches a chip register" in err and err.count("\n") == 1
    (tmp_path / "free").mkdir()   # touches no chip: the batched core runs it (issue 25)
    spec = _one_input_spec(tmp_path / "free", "        rts\n")
    code = main(["check", spec, "--scene", str(tmp_path / "screen.toml"), "--at-line", "48", "--engine", "batch"])
    out = capsys.readouterr().out
    assert code == 0 and "engine with the scene: the batched core" in out


def test_an_unknown_engine_is_refused(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["check", "mul8", "--engine", "gpu"])
    assert exit_.value.code == 2


@pytest.mark.parametrize("sweep, says", [
    ('{"a": np.arange(300)}', "holds 299"),
    ('{"b": np.arange(3)}', "lacks 'a'"),
    ('{"a": np.arange(4).reshape(2, 2)}', "one value per case"),
    ('{"a": np.linspace(0, 1, 4)}', "whole numbers"),
])
def test_a_bad_column_block_is_one_line(tmp_path, capsys, sweep, says):
    spec = _one_input_spec(tmp_path, "        rts\n", 'sweep = "gen.py:sweep"\n')
    (tmp_path / "gen.py").write_text(f"import numpy as np\ndef sweep():\n    return {sweep}\n")
    code = main(["check", spec, "--exhaustive", "--jobs", "1"])
    err = capsys.readouterr().err
    assert code == 2 and "cases.sweep" in err and says in err and err.count("\n") == 1


def test_column_blocks_from_a_sweep_are_run(tmp_path, capsys):
    spec = _one_input_spec(tmp_path, "        rts\n", 'sweep = "gen.py:sweep"\n')
    (tmp_path / "gen.py").write_text("import numpy as np\ndef sweep():\n"
                                     "    for start in (0, 100):\n        yield {'a': np.arange(start, start + 50)}\n")
    code, (record,) = check_json(capsys, spec, "--exhaustive", "--random", "0")
    assert code == 0
    assert [p["cases"] for p in record["coverage"]] == [256, 100]


@pytest.mark.parametrize("body, says", [
    ("return a[:-1]", "shape"),
    ("return a * 1.5", "whole numbers"),
    ("return a + 256", "outside 0..255"),
    ("raise ValueError('no')", "raised ValueError"),
])
def test_an_array_reference_in_the_wrong_shape_is_one_line(tmp_path, capsys, body, says):
    spec = _one_input_spec(tmp_path, "        rts\n")
    text = Path(spec).read_text().replace('function = "ref.py:f"', 'function = "ref.py:f"\narrays = true')
    Path(spec).write_text(text)
    (tmp_path / "ref.py").write_text(f"def f(a):\n    {body}\n")
    code = main(["check", spec, "--engine", "batch", "--jobs", "1"])
    err = capsys.readouterr().err
    assert code == 2 and "arrays = true" in err and says in err and err.count("\n") == 1


def test_a_batch_too_big_for_lane_memory_is_split(monkeypatch):
    """pixel writes its own code per lane: with room for few per-lane bytes the batch is halved until it
    fits, and gives the same outputs and cycles."""
    routine = get("pixel")
    block = next(case_sets.batches(case_sets.plan(routine, exhaustive=False), 512))
    whole = RoutineRunner(routine, routine.seed).run_batch(block)
    small = lambda *args, **kw: batch.BatchCpu(*args, **kw, memory_limit=64 * 4 * 40)  # noqa: E731
    monkeypatch.setattr(batch_runs, "BatchCpu", small)
    split = RoutineRunner(routine, routine.seed).run_batch(block)
    assert all(np.array_equal(a, b) for a, b in zip(whole.outputs, split.outputs))
    assert np.array_equal(whole.cycles, split.cycles)


def test_lane_memory_refuses_past_its_limit():
    memory = lane_memory.LaneMemory(bytes(0x10000), lanes=100, limit=100 * 4 * 3)
    for address in (0x10, 0x11, 0x12):
        memory.row(address)
    with pytest.raises(lane_memory.LaneMemoryFull):
        memory.row(0x13)


def test_auto_takes_the_batched_core_for_large_case_sets(capsys):
    code, (small,) = check_json(capsys, "mul8", "--random", "100")
    code, (large,) = check_json(capsys, "mul8", "--random", str(check_module.AUTO_BATCH_CASES))
    assert (small["engine"], large["engine"]) == ("scalar", "batch")
    with pytest.raises(InputError):
        check_routine("mul8", engine="gpu")


@pytest.mark.exhaustive
@pytest.mark.parametrize("name, sweep", [("mul8", 256 * 256), ("tile", 512 * 256)])
def test_every_input_of_mul8_and_tile_on_the_batched_core(name, sweep, capsys):
    """Truly exhaustive in CI: mul8 every (a, b), tile every 9-bit X by every Y, against the reference."""
    code, (record,) = check_json(capsys, name, "--exhaustive", "--engine", "batch", "--random", "1000")
    assert code == 0 and record["mismatches"] == 0
    assert next(p for p in record["coverage"] if p["part"] == "sweep")["cases"] == sweep
    assert record["engine_agreement"]["cases"] >= 2_000 and record["engine_agreement"]["mismatches"] == 0
