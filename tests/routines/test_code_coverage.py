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


# ---- the coverage-guided search ----------------------------------------------------------------------

MAGIC = """\
        .org $c000
magic:  lda #0
        sta out
        lda a
        cmp #$a7
        bne done
        lda b
        cmp #$3c
        bne done
        ldx #20         ; the slow path: only a = $A7 with b = $3C
slow:   dex
        bne slow
        inc out
done:   lda out
        rts
a:      .byte 0
b:      .byte 0
out:    .byte 0
"""
MAGIC_SPEC = """\
[program]
file = "magic.s"
entry = "magic"

[inputs]
a = {{ at = "a"{a_values} }}
b = "b"

[outputs]
hit = "A"

[reference]
function = "ref.py:magic"

[cases]
random = 2000
{cases}

[cycles]
loops = {{ slow = 20 }}
"""
MAGIC_WORST = 139  # 25 cycles on every other path; the slow path: 20 DEX/BNE rounds (5 * 19 + 4) and INC


def _magic(tmp_path: Path, cases: str = "", a_values: str = "") -> Path:
    (tmp_path / "magic.s").write_text(MAGIC)
    (tmp_path / "ref.py").write_text("def magic(a, b):\n    return 1 if (a, b) == (0xA7, 0x3C) else 0\n")
    spec = tmp_path / "magic.toml"
    spec.write_text(MAGIC_SPEC.format(cases=cases, a_values=a_values))
    return spec


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_the_default_search_finds_the_worst_path_uniform_random_misses(tmp_path, engine):
    spec = _magic(tmp_path)
    without = check(spec, engine=engine, search_budget=0)
    assert without.mismatches == 0 and without.totals.cycles_max < MAGIC_WORST and not without.worst_reached
    report = check(spec, engine=engine)  # the default search
    assert report.mismatches == 0 and report.static.worst == MAGIC_WORST
    assert report.worst_reached and report.totals.max_case == (0xA7, 0x3C)
    assert (0xA7, 0x3C) in report.search.found and report.totals.cases == 2000 + len(report.search.found)
    assert report.code_coverage.executed[0xC015] == 20  # the loop ran, counted like every case's code
    assert report.code_coverage.worst_path.count(0xC015) == 20 and report.code_coverage.worst_cycles == MAGIC_WORST


def test_both_engines_search_alike_and_the_seed_decides(tmp_path):
    spec = _magic(tmp_path)
    scalar, batch = check(spec, engine="scalar"), check(spec, engine="batch")
    assert scalar.search == batch.search and scalar.code_coverage == batch.code_coverage
    assert check(spec, engine="scalar").search == scalar.search  # the same seed: the same search
    assert check(spec, engine="scalar", seed=7).search != scalar.search  # another seed: other candidates


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_the_search_runs_only_candidates_inside_values_and_where(tmp_path, monkeypatch, engine):
    from retro.analysis.check import search

    ran = []
    probe = search._probe
    monkeypatch.setattr(search, "_probe", lambda runner, cases, on_batch: ran.extend(cases) or probe(runner, cases, on_batch))
    spec = _magic(tmp_path, cases='where = "b != 62 and b % 2 == 0"', a_values=', values = [1, 2, 167, 200]')
    report = check(spec, engine=engine, random=20)
    assert len(ran) > 1000  # (the planned random cases are drawn first and filtered: some lie outside)
    assert all(a in (1, 2, 167, 200) and b != 62 and b % 2 == 0 for a, b in ran)
    assert report.worst_reached and (0xA7, 0x3C) in report.search.found  # 60 is even: inside the domain


def test_a_search_budget_in_the_spec_and_at_the_command_line(tmp_path, capsys):
    spec = _magic(tmp_path, cases="search = 0")
    assert check(spec).search.ended == "off"
    assert main(["check", str(spec), "--search", "512", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)[0]
    assert record["search"]["budget"] == 512 and record["search"]["candidates"] <= 512
    worst = record["bounds_reached"]["worst"]
    assert worst["reached"] and worst["inputs"] == {"a": 0xA7, "b": 0x3C} and worst["found_by_search"]
    main(["check", str(spec), "--no-search"])
    text = capsys.readouterr().out
    assert "static worst 139 not reached (whether any input reaches it is not known)" in text


def test_a_bad_search_budget_is_one_line_naming_the_key(tmp_path, capsys):
    spec = _magic(tmp_path, cases="search = -1")
    assert main(["check", str(spec)]) == 2
    assert "cases.search" in capsys.readouterr().err
    assert main(["check", str(_magic(tmp_path)), "--search", "lots"]) == 2
    assert "--search" in capsys.readouterr().err


SAME = """\
        .org $c000
same:   lda a
        sta t
        lda a
        cmp t           ; always equal: the three NOPs never run
        beq done
        nop
        nop
        nop
done:   rts
a:      .byte 0
t:      .byte 0
"""


def test_a_bound_no_input_reaches_is_known_unreachable_when_every_input_ran(tmp_path):
    """The static analysis knows sets of values, not that A equals the byte it was stored to: its worst
    case falls through to the NOPs, which no input can; every input ran, so that is known. By hand:
    LDA, STA, LDA, CMP (abs, 4 each), BEQ taken 3, RTS 6 = 25; the fall-through BEQ 2 + 3 NOPs 6 = 30."""
    (tmp_path / "same.s").write_text(SAME)
    (tmp_path / "ref.py").write_text("def same(a):\n    return a\n")
    spec = tmp_path / "same.toml"
    spec.write_text('[program]\nfile = "same.s"\nentry = "same"\n\n[inputs]\na = "a"\n\n[outputs]\nr = "A"\n\n'
                    '[reference]\nfunction = "ref.py:same"\n\n[cases]\nexhaustive = ["a"]\n')
    report = check(spec, engine="batch")
    assert report.every_input_run and not report.worst_reached
    assert (report.totals.cycles_max, report.static.worst) == (25, 30)
    from retro.commands.check import bounds_reached

    assert bounds_reached(report)["worst"]["unreachable"] is True


WIDE = """\
        .org $c000
wide:   lda w+1
        cmp #$9c        ; w >= $9C00 only from 39,936 on
        bcc small
        lda tbl+2
        cmp #3
        bne small
        lda #1
        rts
small:  lda #0
        rts
w:      .byte 0, 0
tbl:    .byte 0, 0, 0
"""
WIDE_SPEC = """\
[program]
file = "wide.s"
entry = "wide"

[inputs]
w = { at = ["w", "w+1"], values = "100..40000" }
t = { at = "tbl", size = 3, values = "0..3" }

[outputs]
r = "A"

[reference]
function = "ref.py:wide"

[cases]
random = 20
"""


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_the_search_keeps_wide_numbers_and_table_bytes_inside_their_values(tmp_path, monkeypatch, engine):
    from retro.analysis.check import search

    (tmp_path / "wide.s").write_text(WIDE)
    (tmp_path / "ref.py").write_text("def wide(w, t):\n    return 1 if w >= 0x9C00 and t[2] == 3 else 0\n")
    (tmp_path / "wide.toml").write_text(WIDE_SPEC)
    ran = []
    probe = search._probe
    monkeypatch.setattr(search, "_probe", lambda runner, cases, on_batch: ran.extend(cases) or probe(runner, cases, on_batch))
    report = check(tmp_path / "wide.toml", engine=engine)
    assert report.mismatches == 0 and len(ran) > 1000
    assert all(100 <= w <= 40000 and len(t) == 3 and all(0 <= b <= 3 for b in t) for w, t in ran)
    summary = report.code_coverage
    assert all(summary.taken[pc] and summary.not_taken[pc] for pc in summary.taken)  # both ways of both branches
