"""Routine specs of users' own code: every assembler's build, wrong routines, budgets, bad specs.

The boxhit fixtures (tests/data/foreign, real output of ACME, 64tass, ca65, DASM and xa, and a Kick
Assembler .sym written from its documented format) are one routine: its cost is counted by hand
from the datasheet cycles of its instructions:
- fastest: LDA abs 4, CLC 2, ADC abs 4, CMP zp 3, BEQ taken 3 (to miss), CLC 2, RTS 6 = 24;
- slowest: three tests passed (17 + 16 + 17: LDA/CLC/ADC/CMP and two branches not taken), the
  fourth (LDA zp 3, CLC 2, ADC zp 3, CMP abs 4, BEQ 2, BCC taken 3 = 17) missing at its last
  branch, then CLC 2, RTS 6: 17 + 16 + 17 + 17 + 8 = 75.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.commands.cycles import COST_FIELDS
from retro.cli import main

SPECS = Path(__file__).resolve().parents[1] / "data" / "specs"
ASSEMBLERS = ["acme", "64tass", "ca65", "kick", "dasm", "xa", "nes"]
FASTEST, SLOWEST = 24, 75


def _check_json(capsys, *args) -> tuple[int, list[dict]]:
    code = main(["check", *args, "--json", "--jobs", "1"])
    return code, json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("assembler", ASSEMBLERS)
def test_each_assemblers_build_is_checked(assembler, capsys):
    code, (record,) = _check_json(capsys, str(SPECS / f"boxhit_{assembler}.toml"), "--random", "200")
    assert code == 0 and record["mismatches"] == 0
    assert record["min"] == FASTEST and record["max"] == SLOWEST
    assert (record["static_min"], record["static_max"]) == (FASTEST, SLOWEST)
    assert record["budget"] == 80
    # an iNES image runs on the 2A03 and is shown in NES raster lines (341 dots / 3 per CPU cycle)
    assert record["cpu"] == ("2a03" if assembler == "nes" else "6510")
    assert record["machine"] == ("nes" if assembler == "nes" else "c64")
    timeline = record["raster"]["nes_ntsc" if assembler == "nes" else "c64_pal"]
    assert timeline["max_lines"] == round(SLOWEST / (341 / 3 if assembler == "nes" else 63), 3)
    assert set(record["min_inputs"]) == {"ax", "ay", "aw", "ah", "bx", "by", "bw", "bh"}
    # the exhaustive part: every pair of the two left edges (0..255 for ACME, 0..63 in the others)
    exhaustive = next(part for part in record["coverage"] if part["part"] == "exhaustive")
    pairs = 256 * 256 if assembler == "acme" else 64 * 64
    assert exhaustive["cases"] == exhaustive["space"] == pairs and exhaustive["complete"]
    # the 8-bit sums wrap: each "x + w <= 255" condition is shown to be needed
    sums = [item for item in record["domain"] if "+" in item["condition"]]
    assert len(sums) == 4 and all(item["wrong"] > 0 for item in sums), record["domain"]


def test_min_and_max_inputs_cost_what_they_say(capsys):
    code, (record,) = _check_json(capsys, str(SPECS / "boxhit_acme.toml"), "--random", "100")
    fast, slow = record["min_inputs"], record["max_inputs"]
    assert fast["bx"] + fast["bw"] <= fast["ax"]  # B ends before A starts: the first test misses
    # the slowest case passes three tests and fails the last: A's bottom does not reach B's top
    assert fast is not slow and slow["ay"] + slow["ah"] <= slow["by"]
    from retro.routines.registry import get
    from retro.routines.runner import RoutineRunner

    runner = RoutineRunner(get(str(SPECS / "boxhit_acme.toml")))
    names = runner.routine.input_names
    assert runner.run(tuple(fast[n] for n in names))[1] == FASTEST
    assert runner.run(tuple(slow[n] for n in names))[1] == SLOWEST


def test_a_wrong_routine_is_caught_with_its_inputs(capsys):
    # acme_boxhit_wrong.asm lacks the first `beq miss`: B's right edge touching A's left edge is a hit
    code, (record,) = _check_json(capsys, str(SPECS / "boxhit_acme_wrong.toml"), "--random", "0")
    assert code == 1 and record["result_mismatches"] > 0
    failure = record["first_failure"]
    inputs = failure["inputs"]
    assert inputs["bx"] + inputs["bw"] == inputs["ax"]  # touching on x
    assert failure["outputs"] == {"hit": 1} and failure["expected"] == {"hit": 0}
    assert failure["trace"][0].startswith("$C000  LDA $C049")
    main(["check", str(SPECS / "boxhit_acme_wrong.toml"), "--random", "0", "--jobs", "1"])
    text = capsys.readouterr().out
    assert "first failing case: ax=" in text and "routine:   hit=1" in text and "reference: hit=0" in text


def test_a_broken_budget_fails(capsys):
    code, (record,) = _check_json(capsys, str(SPECS / "boxhit_acme_tight_budget.toml"), "--random", "50")
    assert code == 1 and record["mismatches"] == len(record["budget_violations"]) == 2  # measured and static
    assert "over the budget of 60" in record["budget_violations"][0]


def test_cycles_of_a_spec(capsys):
    assert main(["cycles", str(SPECS / "boxhit_ca65.toml"), "--json", "--random", "50", "--jobs", "1"]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert tuple(row) == COST_FIELDS
    assert (row["min"], row["max"], row["budget"]) == (FASTEST, SLOWEST, 80)
    # boxhit's own instructions, $C000 through miss's RTS at $C035 (the listing): not fill, sum or data
    assert row["code_bytes"] == 0xC036 - 0xC000
    assert main(["cycles", str(SPECS / "boxhit_ca65.toml"), "--random", "50", "--jobs", "1"]) == 0
    assert "max 75 vs budget <= 80: kept" in capsys.readouterr().out


def test_tables_flags_memory_words_jsr_and_loops(capsys):
    # scan.s: a table input, the carry as input, X and a 16-bit memory word as outputs, a [memory]
    # block, a JSR to a subroutine with a loop. Cycles counted by hand (datasheet):
    # cheapest (carry clear, key at index 0, no sum carries): 4+2+3+4+2+4+6 + (2 + 8*22 - 1 + 6)
    #   + 2+4+4+3+6 = 227; dearest (carry set, bonus 255, all 255, none found):
    #   28 + (2 + 8*27 - 1 + 6) + (2 + 8*17 - 1 + 2 + 6) = 396. Statically: the indexes are known
    #   (Y from 7 down to 0, X from 0 up to 7) and enemy_x ($C040) + 7 stays in its page, so no read
    #   crosses; LDY #7 ... DEY / BPL runs the sum exactly 8 times: the static bounds are 227-396.
    code, (record,) = _check_json(capsys, str(SPECS / "scan" / "scan.toml"))
    assert code == 0 and record["mismatches"] == 0
    assert (record["min"], record["max"], record["static_min"], record["static_max"]) == (227, 396, 227, 396)
    assert record["max_inputs"] == {"key": 0, "carry": 1, "enemies": [255] * 8}


def _variant(tmp_path: Path, replace: dict[str, str], name: str = "boxhit_acme.toml") -> Path:
    text = (SPECS / name).read_text()
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    for file in SPECS.glob("boxhit_refs.py"):
        (tmp_path / file.name).write_text(file.read_text())
    text = text.replace('"../foreign/', f'"{SPECS.parent / "foreign"}/')
    spec = tmp_path / "spec.toml"
    spec.write_text(text)
    return spec


BAD_SPECS = [
    ({'bx = { at = "boxb_x" }': 'bx = { at = "box_b" }'}, "inputs.bx.at: unknown label 'box_b'"),
    ({'hit = "C"': 'hit = "C"\nextra = { at = "A", colour = 1 }'}, "outputs.extra.colour: unknown key"),
    ({'by = "boxb_y"': 'by = "boxb_x"'}, "inputs.by.at: $C04B is also where inputs.bx goes"),
    ({'bx = { at = "boxb_x" }': 'bx = { at = "boxb_x", values = "0..300" }'}, "does not fit in $C04B"),
    ({'exhaustive = ["ax", "bx"]': 'exhaustive = ["ax", "bx", "ay", "by", "aw"]'}, "is more than 2^32"),
    ({'where = "aw': 'where = "import os or aw'}, "cases.where: not an expression"),
    ({'where = "aw': 'where = "zz >= 1 and aw'}, "cases.where: unknown name 'zz'"),
    ({'"../foreign/acme_boxhit.prg"': '"../foreign/nothing.prg"'}, "program.file: "),
    ({'entry = "boxhit"': 'entry = "boxhit"\ncpu = "z80"'}, "program.cpu: expected one of"),
    ({'entry = "boxhit"': 'entry = "boxhit"\ncpu = "65c03"'}, "program.cpu: expected one of '6510', '2a03', '65c02'"),
    ({'entry = "boxhit"': 'entry = "boxhit"\nmachine = "atari"'}, "program.machine: expected one of 'c64', 'nes', 'none'"),
    ({'entry = "boxhit"': 'entry = "boxhit"\nmachine = "nes"'}, "program.machine: the NES has a 2A03, not the 6510"),
    ({'[cycles]': '[cycles]\nloops = { boxhit = 0 }'}, "cycles.loops.boxhit: 0 is out of range 1.."),
    ({'boxhit_refs.py:boxhit': 'boxhit_refs.py:nothing'}, "reference.function: boxhit_refs.py has no function"),
    ({'max = 80': 'max = 80\n[cycles.extra]'}, "cycles.extra: unknown key"),
    ({'[inputs]': '[inputs\n'}, "not valid TOML"),
    ({'exhaustive = ["ax", "bx"]': 'exhaustive = []', 'random = 3000': 'random = 0'}, "cases: no cases"),
]


@pytest.mark.parametrize("replace, message", BAD_SPECS)
def test_a_bad_spec_is_one_line_exit_2(tmp_path, capsys, replace, message):
    spec = _variant(tmp_path, replace)
    assert main(["check", str(spec), "--random", "10", "--jobs", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and str(spec) in err, err


@pytest.mark.parametrize("body, message", [
    ("    raise ValueError('no boxes today')", "raised ValueError: no boxes today (inputs ax="),
    ("    return {'hit': 1, 'miss': 0}", "returned keys ['hit', 'miss'] for the outputs ['hit']"),
    ("    return 7", "returned 7 for hit: expected a whole number 0..1"),
])
def test_a_reference_that_raises_or_answers_in_the_wrong_shape(tmp_path, capsys, body, message):
    spec = _variant(tmp_path, {"boxhit_refs.py:boxhit": "bad_refs.py:boxhit"})
    (tmp_path / "bad_refs.py").write_text(f"def boxhit(ax, ay, aw, ah, bx, by, bw, bh):\n{body}\n")
    assert main(["check", str(spec), "--random", "10", "--jobs", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err


def test_an_unbounded_loop_is_one_line(tmp_path, capsys):
    spec = SPECS / "scan" / "scan.toml"
    for file in ("scan.s", "scan_ref.py"):
        (tmp_path / file).write_text((spec.parent / file).read_text())
    (tmp_path / "scan.toml").write_text(spec.read_text().replace("loops = { _loop = 8, _sum = 8 }", "loops = { _loop = 8 }"))
    # --quiet: a check that takes over a second also prints progress lines to stderr
    assert main(["check", str(tmp_path / "scan.toml"), "--random", "0", "--jobs", "1", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the loop at $C029 (_sum) needs a bound" in err, err


def test_an_ambiguous_label_lists_its_scopes(tmp_path, capsys):
    spec = _variant(tmp_path, {'"../foreign/acme_boxhit.prg"': '"../foreign/ca65_boxhit.prg"',
                               '"../foreign/acme_boxhit.sym"': '"../foreign/ca65_boxhit.dbg"',
                               'entry = "boxhit"': 'entry = "loop"'})
    assert main(["check", str(spec), "--jobs", "1"]) == 2
    err = capsys.readouterr().err
    assert "fill::loop" in err and "sum::loop" in err and err.count("\n") == 1, err


def test_a_runaway_routine_stops_the_check_with_its_inputs(tmp_path, capsys):
    source = tmp_path / "spin.s"
    source.write_text("        .org $c000\nspin:   cmp #7\n        beq spin\n        rts\n")
    (tmp_path / "ref.py").write_text("def spin(a):\n    return a\n")
    (tmp_path / "spin.toml").write_text('[program]\nfile = "spin.s"\nentry = "spin"\n[inputs]\na = "A"\n'
                                        '[outputs]\na_out = "A"\n[reference]\nfunction = "ref.py:spin"\n'
                                        '[cases]\nexhaustive = ["a"]\n[cycles]\nlimit = 1000\nstatic = false\n')
    code, (record,) = _check_json(capsys, str(tmp_path / "spin.toml"))
    assert code == 1 and record["run_errors"] == 1
    assert record["first_failure"]["inputs"] == {"a": 7} and "cycle budget of 1000" in record["first_failure"]["message"]


def test_a_spec_on_a_scene_counts_bad_line_stalls_from_the_start_line(tmp_path, capsys):
    # 30 NOPs (2 read cycles each) and an RTS: 66 cycles. With the screen on ($D011 = $1B: YSCROLL 3)
    # line 51 is a Bad Line: BA is low from cycle 12 (3 cycles before the c-accesses of cycles
    # 15-54, Bauer 3.6.3), and the CPU, reading in every cycle, stops from cycle 12 through 54:
    # 43 cycles stolen, 109 in all, ending at line 52 cycle 46 (51*63 + 108 = 52*63 + 45).
    # Started at line 50 cycle 1 the same call ends at line 51 cycle 3, before BA falls.
    (tmp_path / "nops.s").write_text("        .org $c000\nnops:\n" + "        nop\n" * 30 + "        rts\n")
    (tmp_path / "ref.py").write_text("def same(a):\n    return a\n")
    (tmp_path / "nops.toml").write_text('[program]\nfile = "nops.s"\nentry = "nops"\n[inputs]\na = "A"\n'
                                        '[outputs]\nresult = "A"\n[reference]\nfunction = "ref.py:same"\n'
                                        '[cases]\nexhaustive = ["a"]\n')
    (tmp_path / "screen.toml").write_text('chip = "vic-ii"\nvideo = "pal"\n[registers]\n"$d011" = 0x1b\n')
    spec, scene = str(tmp_path / "nops.toml"), str(tmp_path / "screen.toml")
    code, (record,) = _check_json(capsys, spec, "--scene", scene, "--at-line", "51")
    assert code == 0 and record["mismatches"] == 0
    assert (record["min"], record["max"], record["static_max"]) == (109, 109, 66)
    on_scene = record["raster"]["scene"]
    assert on_scene["stolen_max"] == 43 and on_scene["max_lines"] == round(109 / 63, 3)
    assert (on_scene["slowest_end_line"], on_scene["slowest_end_cycle"]) == (52, 46)
    code, (record,) = _check_json(capsys, spec, "--scene", scene, "--at-line", "50", "--at-cycle", "1")
    assert record["max"] == 66 and record["raster"]["scene"]["stolen_max"] == 0
    assert (record["raster"]["scene"]["slowest_end_line"], record["raster"]["scene"]["slowest_end_cycle"]) == (51, 3)
    assert main(["cycles", spec, "--at-line", "50"]) == 2
    assert "--at-line and --at-cycle go with --scene" in capsys.readouterr().err


def test_cycle_model_disagreements_are_counted_and_fail(monkeypatch, capsys):
    import retro.analysis.check.engines as check

    # a timing model that disagrees (count_steps sums the timing model's cycles as it counts coverage)
    monkeypatch.setattr(check, "count_steps", lambda coverage, read, steps, cpu: 1)
    code, (record,) = _check_json(capsys, str(SPECS / "boxhit_xa.toml"), "--random", "10")
    assert code == 1 and record["cycle_mismatches"] == record["cases"] > 0
    assert record["first_failure"]["kind"] == "cycles" and "the timing model says 1" in record["first_failure"]["message"]


def test_measured_cycles_outside_the_static_bounds_fail(monkeypatch, capsys):
    import retro.analysis.check.verdicts as check
    from retro.cpu.flow import Bounds

    monkeypatch.setattr(check, "analyse", lambda *args, **kwargs: Bounds(best=FASTEST + 1, worst=SLOWEST - 1,
                                                                          instructions=1))
    code, (record,) = _check_json(capsys, str(SPECS / "boxhit_xa.toml"), "--random", "10")
    assert code == 1 and len(record["bounds_violations"]) == 2
    assert "below the static best case 25" in record["bounds_violations"][0]
    assert "above the static worst case 74" in record["bounds_violations"][1]


def test_the_first_run_failure_stops_the_check(tmp_path, capsys):
    (tmp_path / "brk.s").write_text("        .org $c000\nbrk_it: brk\n")
    (tmp_path / "ref.py").write_text("def f(a):\n    return a\n")
    (tmp_path / "brk.toml").write_text('[program]\nfile = "brk.s"\nentry = "brk_it"\n[inputs]\na = "A"\n'
                                       '[outputs]\nr = "A"\n[reference]\nfunction = "ref.py:f"\n'
                                       '[cases]\nexhaustive = ["a"]\n[cycles]\nstatic = false\n')
    code, (record,) = _check_json(capsys, str(tmp_path / "brk.toml"))
    assert code == 1 and record["run_errors"] == 1 and record["cases"] == 1  # every case would BRK: stop at one
    assert "BRK" in record["first_failure"]["message"]


def test_a_reference_may_import_its_neighbours(tmp_path, capsys):
    spec = _variant(tmp_path, {"boxhit_refs.py:boxhit": "uses_helper.py:boxhit"})
    (tmp_path / "box_maths.py").write_text("def overlap(a, aw, b, bw):\n    return max(a, b) < min(a + aw, b + bw)\n")
    (tmp_path / "uses_helper.py").write_text(
        "from box_maths import overlap\n\n"
        "def boxhit(ax, ay, aw, ah, bx, by, bw, bh):\n    return overlap(ax, aw, bx, bw) and overlap(ay, ah, by, bh)\n")
    code, (record,) = _check_json(capsys, str(spec), "--random", "50")
    assert code == 0 and record["mismatches"] == 0


@pytest.mark.parametrize("machine, timelines", [("none", set()), ("c64", {"c64_pal", "c64_ntsc"}),
                                                 ("C64", {"c64_pal", "c64_ntsc"})])
def test_the_raster_figures_follow_the_named_machine(tmp_path, capsys, machine, timelines):
    """6510 code from another computer (a VIC-20, an Atari 2600) names no machine: no C64 raster lines."""
    spec = _variant(tmp_path, {'entry = "boxhit"': f'entry = "boxhit"\nmachine = "{machine}"'})
    code, (record,) = _check_json(capsys, str(spec), "--random", "50")
    assert code == 0 and record["machine"] == machine.lower() and set(record["raster"]) == timelines
    assert main(["check", str(spec), "--random", "50", "--jobs", "1"]) == 0
    assert ("raster (CPU never stalled): C64 PAL" in capsys.readouterr().out) == bool(timelines)


@pytest.mark.parametrize("cpu", ["6510", "65c02"])
def test_an_ines_image_is_checked_on_the_2a03_only(tmp_path, capsys, cpu):
    spec = _variant(tmp_path, {'entry = "boxhit"': f'entry = "boxhit"\ncpu = "{cpu}"'}, name="boxhit_nes.toml")
    assert main(["check", str(spec), "--random", "10", "--jobs", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"program.cpu: nes_boxhit.nes is a program for the 2A03, not the {cpu.upper()}" in err
