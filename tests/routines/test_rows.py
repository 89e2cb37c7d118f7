"""Expected rows in a routine spec (retro.routines.rows, retro.analysis.row_check).

Every cycle count below is counted by hand from the datasheet cycles of the instructions (MOS
6500 family manual), never taken from a run:
- mulshift (examples/rows_only): 134 + 4 per 1 bit of a (the example's source says how);
- sum3 below: CLC 2, ADC abs 4 three times, RTS 6 = 20;
- boxhit (examples/boxhit, ACME): B's right edge on A's left edge misses at the first BEQ: LDA abs 4,
  CLC 2, ADC abs 4, CMP zp 3, BEQ taken 3, CLC 2, RTS 6 = 24 (tests/routines/test_user_specs.py).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from retro.cli import main
from retro.testing import check, report_text, spec_from_dict

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "rows_only" / "mulshift.toml"
BOXHIT = ROOT / "examples" / "boxhit"

SUM3 = """\
        .org $c000
sum3:   clc
        adc tbl
        adc tbl+1
        adc tbl+2
        rts
tbl:    .byte 0, 0, 0
"""
SUM3_SPEC = """\
{rows}
[program]
file = "sum3.s"
entry = "sum3"

[inputs]
a = "A"
t = {{ at = "tbl", size = 3, values = "0..255" }}

[outputs]
a = "A"
c = "C"
{rest}"""

BREAKS = """\
        .org $c000
breaks: lda $fb
        beq stop
        rts
stop:   brk
"""
BREAKS_SPEC = """\
rows = [
  { a = 1, out = 1 },
  { a = 0, out = 0, note = "BRK" },
  { a = 2, out = 2 },
]

[program]
file = "breaks.s"
entry = "breaks"

[inputs]
a = "$fb"

[outputs]
out = "A"
"""


def _check_json(capsys, *args) -> tuple[int, list[dict]]:
    code = main(["check", *map(str, args), "--json", "--jobs", "1"])
    return code, json.loads(capsys.readouterr().out)


def _sum3(tmp_path: Path, rows: str, rest: str = "", name: str = "sum3") -> Path:
    (tmp_path / "sum3.s").write_text(SUM3)
    spec = tmp_path / f"{name}.toml"  # a new name per spec: a rewrite within a clock tick reads as unchanged
    spec.write_text(SUM3_SPEC.format(rows=rows, rest=rest))
    return spec


def _mulshift(tmp_path: Path, rows: str) -> Path:
    shutil.copy(EXAMPLE.with_suffix(".s"), tmp_path / "mulshift.s")
    text = EXAMPLE.read_text()
    start, end = text.index("rows = ["), text.index("]\n\n[program]") + 2
    spec = tmp_path / "mulshift.toml"
    spec.write_text(text[:start] + rows + text[end:])
    return spec


# ---- a spec of rows only -----------------------------------------------------------------------------

def test_the_rows_only_example_holds_on_both_engines_with_the_same_json(capsys):
    records = {}
    for engine in ("scalar", "batch"):
        code, (record,) = _check_json(capsys, EXAMPLE, "--engine", engine)
        assert code == 0 and record["mismatches"] == 0 and record["engine"] == engine
        records[engine] = record
    scalar, batch = records["scalar"], records["batch"]
    assert scalar["rows"] == batch["rows"]
    assert scalar["rows"]["rows"] == scalar["rows"]["held"] == 4 and scalar["rows"]["failures"] == []
    # the rows are the check's only cases: counted, and the cycle figures are theirs
    assert scalar["cases"] == batch["cases"] == 4
    assert scalar["coverage"] == batch["coverage"] == [{"part": "rows", "cases": 4}]
    for key in ("min", "max", "mean", "min_inputs", "max_inputs"):
        assert scalar[key] == batch[key], key
    assert (scalar["min"], scalar["max"]) == (134, 166)
    assert scalar["min_inputs"] == {"a": 0, "b": 0} and scalar["max_inputs"] == {"a": 255, "b": 255}
    assert batch["engine_agreement"] == {"cases": 4, "mismatches": 0, "timing_model_mismatches": 0}


def test_a_rows_only_spec_says_why_its_static_bounds_are_unknown(capsys):
    code, (record,) = _check_json(capsys, EXAMPLE)
    assert code == 0 and record["static_min"] is None and record["static_max"] is None
    assert "the loop at $C006 (loop) needs a bound" in record["rows"]["static_note"]
    main(["check", str(EXAMPLE)])
    text = capsys.readouterr().out
    assert "static bounds unknown;" in text.splitlines()[0]
    assert "static bounds unknown (a spec of rows only): mulshift: the loop at $C006" in text


def test_a_rows_only_spec_with_loop_bounds_gets_static_bounds():
    import tomllib

    doc = tomllib.loads(EXAMPLE.read_text())
    doc["cycles"] = {"loops": {"loop": 8}, "max": 166}
    report = check(spec_from_dict(doc, base=EXAMPLE.parent))
    assert report.mismatches == 0 and report.static.worst == 166 and not report.rows.static_note
    doc["cycles"]["max"] = 165  # the budget covers the rows too: the $FF row takes 166
    report = check(spec_from_dict(doc, base=EXAMPLE.parent))
    assert report.mismatches == 2 and len(report.budget_violations) == 2  # measured and static worst


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_failing_row_is_reported_with_inputs_expected_and_got(tmp_path, capsys, engine):
    spec = _mulshift(tmp_path, """rows = [
  { a = 3, b = 5, product = 15 },
  { a = 3, b = 5, product = 16, note = "off by one" },
  { a = 1, b = 1, cycles = 139, max_cycles = 137 },
]""")
    code, (record,) = _check_json(capsys, spec, "--engine", engine)
    assert code == 1 and record["mismatches"] == 2
    rows = record["rows"]
    assert (rows["rows"], rows["held"], rows["failed"]) == (3, 1, 2)
    wrong, slow = rows["failures"]
    assert wrong == {"row": 1, "note": "off by one", "inputs": {"a": 3, "b": 5}, "expected": {"product": 16},
                     "outputs": {"product": 15}, "cycles": 142, "expected_cycles": None, "max_cycles": None,
                     "reference": None, "problems": ["product: expected 16, got 15"]}
    # a row that states no output compares none; a = 1 has one 1 bit: 138 cycles
    assert slow["expected"] == {} and slow["outputs"] == {"product": 1} and slow["cycles"] == 138
    assert slow["problems"] == ["cycles: expected 139, got 138", "cycles: 138 is over max_cycles 137"]
    failure = record["first_failure"]
    assert failure["kind"] == "row" and failure["inputs"] == {"a": 3, "b": 5}
    assert failure["expected"] == {"product": 16} and failure["outputs"] == {"product": 15}
    assert failure["message"].startswith("rows[1] (off by one): product: expected 16")
    assert failure["trace"][0].startswith("$C000  LDA #$00")
    main(["check", str(spec), "--engine", engine])
    text = capsys.readouterr().out
    assert "  rows: 3, 1 hold, 2 fail" in text
    assert "  ROW rows[1] (off by one): a=3, b=5 -> expected product=16, got product=15: product: expected 16, got 15" in text
    assert "    routine:   product=15\n    the row:   product=16\n" in text


def test_both_engines_give_the_same_json_for_failing_rows(tmp_path, capsys):
    spec = _mulshift(tmp_path, """rows = [
  { a = 3, b = 5, product = 16 },
  { a = 255, b = 2, product = 510, cycles = 165 },
]""")
    records = [_check_json(capsys, spec, "--engine", engine)[1][0] for engine in ("scalar", "batch")]
    assert records[0]["rows"] == records[1]["rows"] and records[0]["rows"]["failed"] == 2
    assert records[0]["first_failure"] == records[1]["first_failure"]


def test_a_call_that_stops_stops_the_rows_on_both_engines(tmp_path, capsys):
    (tmp_path / "breaks.s").write_text(BREAKS)
    spec = tmp_path / "breaks.toml"
    spec.write_text(BREAKS_SPEC)
    records = []
    for engine in ("scalar", "batch"):
        code, (record,) = _check_json(capsys, spec, "--engine", engine)
        assert code == 1 and record["run_errors"] == 1 and record["cases"] == 2
        records.append(record)
    assert records[0]["rows"] == records[1]["rows"]
    rows = records[0]["rows"]
    assert (rows["held"], rows["failed"], rows["not_checked"]) == (1, 1, [2])
    (stopped,) = rows["failures"]
    assert stopped["row"] == 1 and "BRK" in stopped["problems"][0] and stopped["outputs"] is None
    assert records[0]["first_failure"]["kind"] == records[1]["first_failure"]["kind"] == "run"
    assert records[0]["mismatches"] == 1  # the stopped call is the run error, counted once
    main(["check", str(spec)])
    assert "  rows: 3, 1 hold, 1 fail, 1 not checked (after the call of rows[1] stopped)" in capsys.readouterr().out


# ---- rows beside a reference -------------------------------------------------------------------------

def _boxhit_with_rows(rows: list[dict]) -> dict:
    import tomllib

    doc = tomllib.loads((BOXHIT / "boxhit.toml").read_text())
    doc["cases"]["random"] = 50
    doc["rows"] = rows
    return doc


def test_rows_run_beside_the_reference_and_fail_on_their_own():
    touching = {"ax": 18, "ay": 0, "aw": 8, "ah": 8, "bx": 10, "by": 0, "bw": 8, "bh": 8}
    report = check(spec_from_dict(_boxhit_with_rows([{**touching, "hit": False, "cycles": 24}]), base=BOXHIT))
    assert report.mismatches == 0 and report.rows.outcomes[0].holds
    assert [p.name for p in report.parts][:2] == ["rows", "exhaustive"]
    assert report.totals.cases == 1 + 65_536 + 50 and report.totals.cycles_min == 24
    # the reference agrees with the routine; a row that states otherwise fails by itself
    report = check(spec_from_dict(_boxhit_with_rows([{**touching, "hit": 1}]), base=BOXHIT))
    assert report.mismatches == 1 and report.totals.result_mismatches == 0
    (wrong,) = report.rows.failing
    assert wrong.problems == ("hit: expected 1, got 0",) and wrong.reference == (0,)  # the row is what is wrong
    assert "hit: expected 1, got 0 (the reference says hit=0)" in report_text(report)


# ---- the notation --------------------------------------------------------------------------------------

def test_every_number_notation_flags_tables_and_shared_names(tmp_path, capsys):
    # sum3 adds A and three table bytes with carry; `a` is both an input and an output
    spec = _sum3(tmp_path, """rows = [
  { in.a = 1, t = [1, 2, "$03"], out.a = 7, c = false, cycles = 20 },
  { in.a = "$FF", t = "01 00 00", out.a = "%1", c = 0 },
  { in.a = 0xFF, t = [1, 0b11111111, "0xff"], out.a = 0, c = true },
]""")
    code, (record,) = _check_json(capsys, spec)
    assert code == 0 and record["rows"]["held"] == 3, record["rows"]
    # the same rows as [[rows]] tables read the same
    tables = _sum3(tmp_path, '''[[rows]]
in.a = 1
t = [1, 2, 3]
out.a = 8
c = false
''', name="tables")
    code, (record,) = _check_json(capsys, tables)
    assert code == 1 and record["rows"]["failures"][0]["problems"] == ["a: expected 8, got 7"]


def _error(capsys, spec: Path) -> str:
    assert main(["check", str(spec)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    return err.strip()


@pytest.mark.parametrize("rows, message", [
    ('rows = [{ in.a = 1, t = [1, 2, 3], out.a = 6, zz = 1 }]',
     "rows[0].zz: neither an input nor an output (inputs: a, t; outputs: a, c; a row's own keys: cycles, max_cycles"),
    ('rows = [{ in.a = 1, t = [1, 2, 3], c = 0 }, { in.a = 1, c = 0 }]',
     "rows[1].t: missing: a row gives every input (a, t)"),
    ('rows = [{ in.a = 256, t = [1, 2, 3], c = 0 }]', "rows[0].in.a:"),
    ('rows = [{ in.a = 1, t = [1, 2, 3], c = 2 }]', "rows[0].c:"),
    ('rows = [{ in.a = 1.5, t = [1, 2, 3], c = 0 }]', "rows[0].in.a: expected an integer, got 1.5"),
    ('rows = [{ in.a = true, t = [1, 2, 3], c = 0 }]', "rows[0].in.a: expected an integer, got true"),
    ('rows = [{ in.a = "$1G", t = [1, 2, 3], c = 0 }]', "rows[0].in.a:"),
    ('rows = [{ in.a = 1, t = [1, 2], c = 0 }]', "rows[0].t: expected 3 bytes (3 bytes at $C00B), got 2"),
    ('rows = [{ in.a = 1, t = [1, 2, 300], c = 0 }]', "rows[0].t[2]:"),
    ('rows = [{ in.a = 1, t = [1, 2, 3] }]', "rows[0]: states no output, cycles or max_cycles: nothing to check"),
    ('rows = [{ a = 1, t = [1, 2, 3], c = 0 }]', "rows[0].a: 'a' is both an input and an output: write in.a or out.a"),
    ('rows = [{ in.zz = 1, t = [1, 2, 3], c = 0 }]', "rows[0].in.zz: no input of that name (inputs: a, t)"),
    ('rows = [{ in.a = 1, t = [1, 2, 3], out.t = [1, 2, 3] }]', "rows[0].out.t: no output of that name"),
    ('rows = [{ in.a = 1, t = [1, 2, 3], c = 0, cycles = 0 }]', "rows[0].cycles:"),
    ('rows = [{ in.a = 1, t = [1, 2, 3], c = 0, max_cycles = "many" }]', "rows[0].max_cycles:"),
    ('rows = [{ in.a = 1, t = [1, 2, 3], c = 0, note = 3 }]', "rows[0].note: expected one line"),
    ('rows = [{ t = [1, 2, 3], c = 0, in = 3 }]', "rows[0].in: expected a table, got 3"),
    ('rows = []', "rows: the list of rows is empty"),
    ('rows = [1, 2]', "rows[0]: expected a table, got 1"),
    ('[rows]\na = 1', "rows: expected an array of rows"),
])
def test_each_bad_row_is_one_line_naming_file_row_and_key(tmp_path, capsys, rows, message):
    spec = _sum3(tmp_path, rows)
    err = _error(capsys, spec)
    assert err.startswith(f"retro check: {spec}: ") and message in err, err


def test_rows_below_a_table_header_are_named_as_such(tmp_path, capsys):
    spec = _sum3(tmp_path, "", rest='rows = [{ in.a = 1, t = [1, 2, 3], c = 0 }]\n')
    assert "outputs.rows: rows written below [outputs] belong to that table in TOML" in _error(capsys, spec)


def test_without_rows_a_reference_is_required_and_without_one_no_cases(tmp_path, capsys):
    spec = _sum3(tmp_path, "")
    assert "reference: missing: the [reference] table, or [[rows]]" in _error(capsys, spec)
    spec = _sum3(tmp_path, 'rows = [{ in.a = 1, t = [1, 2, 3], c = 0 }]', rest="[cases]\nrandom = 10\n", name="cases")
    assert "cases: without a [reference] no answer is known for generated cases" in _error(capsys, spec)


def test_a_rows_only_spec_runs_its_rows_whatever_random_and_exhaustive_say(capsys):
    code, (record,) = _check_json(capsys, EXAMPLE, "--random", "50", "--exhaustive")
    assert code == 0 and record["cases"] == 4 and record["coverage"] == [{"part": "rows", "cases": 4}]


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_row_whose_call_stops_stops_the_generated_cases_too(tmp_path, capsys, engine):
    (tmp_path / "breaks.s").write_text(BREAKS)
    (tmp_path / "ref.py").write_text("def same(a):\n    return a\n")
    spec = tmp_path / "breaks.toml"
    spec.write_text(BREAKS_SPEC + '\n[reference]\nfunction = "ref.py:same"\n\n[cases]\nrandom = 100\n'
                                  'where = "a != 0"\n\n[cycles]\nstatic = false\n')
    code, (record,) = _check_json(capsys, spec, "--engine", engine)
    assert code == 1 and record["run_errors"] == 1 and record["cases"] == 2
    assert record["coverage"] == [{"part": "rows", "cases": 2}]
    if engine == "batch":  # no Machine run of the generated cases either
        assert record["engine_agreement"]["cases"] == 2


def test_many_rows_run_in_batches_of_bounded_width(monkeypatch):
    import tomllib

    import retro.analysis.row_check as row_check

    monkeypatch.setattr(row_check, "BATCH_LANES", 7)  # 156 rows: 23 batches, the last one short
    doc = tomllib.loads(EXAMPLE.read_text())
    doc["rows"] = [{"a": a, "b": b, "product": a * b, "cycles": 134 + 4 * bin(a).count("1")}
                   for a in range(0, 256, 5) for b in (0, 7, 255)]
    doc["rows"][40]["product"] += 1
    results = []
    for engine in ("scalar", "batch"):
        report = check(spec_from_dict(doc, base=EXAMPLE.parent), engine=engine)
        assert report.totals.cases == 156 and report.mismatches == 1
        results.append([(o.outputs, o.cycles, o.problems) for o in report.rows.outcomes])
    assert results[0] == results[1]
    assert results[0][40][2] == (f"product: expected {doc['rows'][40]['product']}, got {doc['rows'][40]['product'] - 1}",)


def test_a_wrong_row_shows_the_references_answer_unless_it_refuses(tmp_path, capsys):
    (tmp_path / "breaks.s").write_text(BREAKS)
    (tmp_path / "ref.py").write_text("def same(a):\n    if a == 2:\n        raise ValueError('not mine')\n    return a\n")
    spec = tmp_path / "refused.toml"
    spec.write_text('rows = [{ a = 1, out = 5 }, { a = 2, out = 7 }]\n'
                    + BREAKS_SPEC[BREAKS_SPEC.index("[program]"):]
                    + '\n[reference]\nfunction = "ref.py:same"\n\n[cases]\nrandom = 20\nwhere = "a != 0 and a != 2"\n'
                      '\n[cycles]\nstatic = false\n')
    records = [_check_json(capsys, spec, "--engine", engine)[1][0] for engine in ("scalar", "batch")]
    assert records[0]["rows"] == records[1]["rows"]
    first, second = records[0]["rows"]["failures"]
    assert first["reference"] == {"out": 1} and first["outputs"] == {"out": 1}
    assert second["reference"] is None and second["outputs"] == {"out": 2}


def test_a_row_the_engines_disagree_on_fails_naming_the_row(capsys, monkeypatch):
    """The rows' calls on the batched core are held against Machine's, call for call: a batched core
    one cycle slow on every call is a failure naming the first row."""
    import dataclasses

    from retro.routines.runner import RoutineRunner

    real = RoutineRunner.run_batch

    def one_cycle_slow(self, columns, *args, **kwargs):
        outcome = real(self, columns, *args, **kwargs)
        return dataclasses.replace(outcome, cycles=outcome.cycles + 1)

    monkeypatch.setattr(RoutineRunner, "run_batch", one_cycle_slow)
    code, (record,) = _check_json(capsys, EXAMPLE, "--engine", "batch")
    assert code == 1
    assert record["engine_agreement"]["cases"] == 4 and record["engine_agreement"]["mismatches"] == 4
    # three rows state their cycles and fail on their own; all four calls are engine disagreements
    assert record["rows"]["failed"] == 3
    code = main(["check", str(EXAMPLE), "--engine", "batch", "--jobs", "1"])
    text = capsys.readouterr().out
    assert code == 1 and "on 4 of the calls Machine agrees on 0 and the timing model on 4" in text, text


def test_the_rows_machine_calls_are_held_to_the_timing_model_naming_the_row(capsys, monkeypatch):
    """On the batched core the rows' calls also run on Machine are tallied as any part's (count_block):
    a timing model one cycle off on the second row is one timing-model mismatch, the first failure
    naming that row; the rows themselves still hold."""
    import dataclasses

    from retro.analysis import row_check

    real = row_check.run_on_machine

    def second_row_mistimed(runner, cases, *args, **kwargs):
        block = real(runner, cases, *args, **kwargs)
        modelled = block.modelled.copy()
        modelled[1] += 1
        return dataclasses.replace(block, modelled=modelled)

    monkeypatch.setattr(row_check, "run_on_machine", second_row_mistimed)
    code, (record,) = _check_json(capsys, EXAMPLE, "--engine", "batch")
    assert code == 1
    assert record["engine_agreement"] == {"cases": 4, "mismatches": 0, "timing_model_mismatches": 1}
    assert record["rows"]["failed"] == 0
    failure = record["first_failure"]
    assert failure["kind"] == "cycles" and failure["inputs"] == {"a": 3, "b": 5}, failure
    assert failure["message"].startswith("rows[1]: measured 142 cycles, the timing model says 143"), failure
