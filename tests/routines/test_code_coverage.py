"""Coverage of the code over a check's cases: counted by hand on a small routine, and equal on both
engines for the built-in routines (retro.analysis.check.coverage)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.cli import main
from retro.testing import check

ROOT = Path(__file__).resolve().parents[2]

SELECT = """\
        .org $c000
sel:    cmp #3          ; $C000  2
        bcs high        ; $C002  2, 3 taken (same page)
        lda $c0fe,x     ; $C004  4, 5 across a page (x >= 2)
        rts             ; $C007  6
high:   lda #0          ; $C008  2
        rts             ; $C00A  6
"""
SELECT_SPEC = """\
rows = [{rows}]

[program]
file = "select.s"
entry = "sel"

[inputs]
a = "A"
x = "X"

[outputs]
r = "A"
"""
ALL_ROWS = [(0, 0), (1, 3), (5, 0), (7, 1)]


def _select(tmp_path: Path, rows: list[tuple[int, int]]) -> Path:
    (tmp_path / "select.s").write_text(SELECT)
    spec = tmp_path / "select.toml"
    spec.write_text(SELECT_SPEC.format(rows=", ".join(f"{{ a = {a}, x = {x}, max_cycles = 99 }}" for a, x in rows)))
    return spec


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_hand_counted_routine(tmp_path, engine):
    coverage = check(_select(tmp_path, ALL_ROWS), engine=engine).code_coverage
    assert coverage.executed == {0xC000: 4, 0xC002: 4, 0xC004: 2, 0xC007: 2, 0xC008: 2, 0xC00A: 2}
    assert coverage.taken == {0xC002: 2} and coverage.not_taken == {0xC002: 2}
    assert coverage.cycles_min == {0xC000: 2, 0xC002: 2, 0xC004: 4, 0xC007: 6, 0xC008: 2, 0xC00A: 6}
    assert coverage.cycles_max == {0xC000: 2, 0xC002: 3, 0xC004: 5, 0xC007: 6, 0xC008: 2, 0xC00A: 6}
    # the slowest case is a = 1, x = 3: 2 + 2 + 5 + 6 cycles
    assert coverage.worst_path == (0xC000, 0xC002, 0xC004, 0xC007) and coverage.worst_cycles == 15


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_what_was_not_run_is_named_in_text_and_json(tmp_path, capsys, engine):
    spec = _select(tmp_path, [(0, 0), (2, 2)])
    assert main(["check", str(spec), "--engine", engine]) == 0
    text = capsys.readouterr().out
    assert ("  code: 4/6 instructions, 1/2 branch directions; not run: $C008 (high), $C00A (high+2), "
            "$C002 (sel+2) taken\n") in text
    main(["check", str(spec), "--engine", engine, "--json"])
    record = json.loads(capsys.readouterr().out)[0]["code_coverage"]
    assert record == {"instructions": 6, "instructions_run": 4, "branch_directions": 2, "branch_directions_run": 1,
                      "not_run": [{"address": "$C008", "label": "high"}, {"address": "$C00A", "label": "high+2"}],
                      "branch_directions_not_run": [{"address": "$C002", "label": "sel+2", "direction": "taken"}]}


@pytest.mark.parametrize("name", ["aabb8", "mul8", "tile", "pixel", "circle_r", "aabb_sprite",
                                  str(ROOT / "examples" / "65c02_boxhit" / "hit65.toml")])
def test_both_engines_give_the_same_coverage(name):
    from retro.analysis.check import run_checks

    scalar, = run_checks([name], engine="scalar", random_count=300, jobs=1)
    batch, = run_checks([name], engine="batch", random_count=300, jobs=1)
    assert scalar.totals.cases == batch.totals.cases and scalar.mismatches == batch.mismatches == 0
    assert scalar.code_coverage == batch.code_coverage
    assert sum(scalar.code_coverage.executed.values()) > scalar.totals.cases  # something was counted
    assert scalar.code_coverage.worst_cycles == scalar.totals.cycles_max


def test_coverage_merges_across_worker_processes():
    from retro.analysis.check import run_checks

    one, = run_checks(["tile"], engine="scalar", random_count=3000, jobs=1)
    two, = run_checks(["tile"], engine="scalar", random_count=3000, jobs=2)
    assert one.code_coverage == two.code_coverage
