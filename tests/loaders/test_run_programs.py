"""`retro run` over every assembler's build of `boxhit`: one spec, every program and symbol format.

boxhit's answer is checked against the definition (A.x < B.x + B.w and B.x < A.x + A.w, the same
for y); its cycles are counted by hand from the MOS datasheet timings of the path it takes (LDA abs 4,
CLC 2, ADC abs 4, CMP zp 3, LDA zp 3, ADC zp 3, CMP abs 4, branch 2 / 3 taken on the same page,
SEC 2, RTS 6).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.commands.run import run as run_routine
from retro.cli import main
from retro.errors import InputError
from retro.paths import EXAMPLES_DIR

FOREIGN = Path(__file__).resolve().parent.parent / "data" / "foreign"

BUILDS = [  # (program, symbol file, load address)
    ("acme_boxhit.prg", "acme_boxhit.sym", None),
    ("acme_boxhit.prg", "acme_boxhit.lbl", None),
    ("64tass_boxhit.prg", "64tass_boxhit.labels", None),
    ("64tass_boxhit.prg", "64tass_boxhit.vicenum", None),
    ("64tass_boxhit.prg", "64tass_boxhit.dump", None),
    ("64tass_boxhit.bin", "64tass_boxhit.dump", "$c000"),
    ("ca65_boxhit.prg", "ca65_boxhit.lbl", None),
    ("ca65_boxhit.prg", "ca65_boxhit.dbg", None),
    ("dasm_boxhit.prg", "dasm_boxhit.sym", None),
    ("xa_boxhit.bin", "xa_boxhit.labels", "$c000"),
    ("acme_boxhit.prg", "kick_boxhit.sym", None),
    ("acme_boxhit.prg", "kick_boxhit.vs", None),
    ("nes_boxhit.nes", "nes_boxhit.dbg", None),
    ("nes_boxhit.nes", "nes_boxhit.lbl", None),
]

AXIS_PASSES = 4 + 2 + 4 + 3 + 2 + 2 + 3 + 2 + 3 + 4 + 2 + 2  # one axis, both compares fall through: 33
CASES = [  # (box A, box B) as (x, y, w, h), carry, cycles
    ((10, 20, 5, 5), (14, 22, 3, 3), 1, 2 * AXIS_PASSES + 2 + 6),                 # overlap: SEC, RTS
    ((10, 20, 4, 5), (14, 20, 3, 5), 0, (4 + 2 + 4 + 3 + 2 + 2) + (3 + 2 + 3 + 4 + 3) + 2 + 6),  # touch in x
    ((100, 0, 8, 8), (0, 0, 10, 8), 0, (4 + 2 + 4 + 3 + 2 + 3) + 2 + 6),          # B left of A: BCC taken
    ((0, 50, 8, 8), (4, 0, 8, 50), 0, AXIS_PASSES + (4 + 2 + 4 + 3 + 3) + 2 + 6),  # B above, touching in y
]


def overlaps(a, b) -> int:
    ax, ay, aw, ah = a
    bx, by, bw, bh = b
    return int(ax < bx + bw and bx < ax + aw and ay < by + bh and by < ay + ah)


def box_sets(a, b) -> list[str]:
    return [f"box{box}_{field}={value}" for box, values in (("a", a), ("b", b))
            for field, value in zip("xywh", values)]


@pytest.mark.parametrize("program, symbols, load", BUILDS)
@pytest.mark.parametrize("a, b, carry, cycles", CASES)
def test_boxhit_from_every_assembler(program, symbols, load, a, b, carry, cycles):
    assert overlaps(a, b) == carry  # the case table agrees with the definition
    report = run_routine(FOREIGN / program, "boxhit", labels=FOREIGN / symbols, load=load, sets=box_sets(a, b))
    assert (report.result.p & 1, report.result.cycles) == (carry, cycles)
    assert report.machine.variant == ("2a03" if program.endswith(".nes") else "6510")


@pytest.mark.parametrize("symbols, sum_loop", [("ca65_boxhit.dbg", "sum::loop"), ("64tass_boxhit.dump", "sum.loop"),
                                               ("dasm_boxhit.sym", "2.loop"), ("ca65_boxhit.lbl", "loop@$C043")])
def test_scoped_routines_by_qualified_names(symbols, sum_loop):
    prg = FOREIGN / symbols.replace(symbols.split("_boxhit")[1], ".prg")
    filled = run_routine(prg, "fill", labels=FOREIGN / symbols, a=7, peeks=["buf:4"])
    assert filled.peeks["buf"] == [7, 7, 7, 7]
    summed = run_routine(prg, "sum", labels=FOREIGN / symbols, sets=["buf=1,2,3,250"])
    assert (summed.result.a, summed.result.x) == ((1 + 2 + 3 + 250) % 256, 0xFF)
    assert run_routine(prg, sum_loop, labels=FOREIGN / symbols, sets=["buf=1,2,3,4"], x=1).result.a == 2 + 1
    with pytest.raises(InputError, match="label 'loop' is defined more than once"):
        run_routine(prg, "loop", labels=FOREIGN / symbols)


def run_cli(capsys, *argv) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_flags_in_and_the_flag_display(capsys, tmp_path):
    php_pla = tmp_path / "p.bin"
    php_pla.write_bytes(bytes([0x08, 0x68, 0x60]))  # PHP / PLA / RTS: A = P as pushed (B and bit 5 set)
    code, out, err = run_cli(capsys, "run", php_pla, "--load", "$1000", "--entry", "$1000",
                             "--c", "1", "--d", "1", "--i", "0", "--v", "1", "--n", "0", "--z", "1")
    assert (code, err) == (0, "")
    lines = out.splitlines()
    assert lines[0].startswith("A=$7B ")  # V D Z C + B + bit 5: $40 | $08 | $02 | $01 | $10 | $20
    assert lines[1] == "N V - B D I Z C"
    # P after PLA: A=$7B sets neither N nor Z; V, D and C stay; bit 5 reads as 1, B is not in P
    assert lines[2] == "0 1 1 0 1 0 0 1"


@pytest.mark.parametrize("flag, value", [("--c", "2"), ("--z", "x")])
def test_a_flag_is_0_or_1(capsys, flag, value):
    code, out, err = run_cli(capsys, "run", FOREIGN / "acme_boxhit.prg", "--entry", "$c000", flag, value)
    assert code == 2 and out == "" and err.count("\n") == 1 and flag in err


def test_a_label_without_symbols_says_what_to_pass(capsys):
    prg = FOREIGN / "acme_boxhit.prg"
    code, out, err = run_cli(capsys, "run", prg, "--entry", "boxhit")
    assert code == 2 and out == ""
    assert err == (f"retro run: {prg} has no symbols: pass --labels with the symbol file your assembler wrote, "
                   f"or give --entry as an address\n")
    assert run_cli(capsys, "run", prg, "--entry", "$c034")[0] == 0  # miss: CLC / RTS


def test_nes_image_runs_on_the_2a03_with_its_symbols(capsys):
    code, out, _ = run_cli(capsys, "run", FOREIGN / "nes_boxhit.nes", "--labels", FOREIGN / "nes_boxhit.lbl",
                           "--entry", "boxhit", *[f"--set={s}" for s in box_sets((10, 20, 5, 5), (14, 22, 3, 3))],
                           "--json")
    report = json.loads(out)
    assert code == 0 and report["p"] & 1 == 1 and report["cycles"] == CASES[0][3]


def test_raw_binary_without_load_and_foreign_source_are_one_line(capsys):
    code, _, err = run_cli(capsys, "run", FOREIGN / "xa_boxhit.bin", "--entry", "$c000")
    assert code == 2 and err.count("\n") == 1 and "pass --load ADDR" in err
    code, _, err = run_cli(capsys, "run", FOREIGN / "acme_boxhit.asm", "--entry", "boxhit")
    assert code == 2 and "not Ophis source (looks like ACME)" in err


def test_asm_refuses_foreign_and_binary_files(capsys, tmp_path):
    out_prg = tmp_path / "x.prg"
    code, _, err = run_cli(capsys, "asm", FOREIGN / "ca65_boxhit.s", "-o", out_prg)
    assert code == 2 and err == (f"retro asm: {FOREIGN / 'ca65_boxhit.s'}: not Ophis source (looks like ca65); "
                                 f"assemble it with your assembler and pass the .prg and --labels\n")
    code, _, err = run_cli(capsys, "asm", FOREIGN / "acme_boxhit.prg", "-o", out_prg)
    assert code == 2 and "not Ophis source (a binary file)" in err and not out_prg.exists()


def test_a_scene_for_another_cpu_than_the_programs_is_one_line(capsys):
    scene = EXAMPLES_DIR / "vic_two_balls.toml"
    code, _, err = run_cli(capsys, "run", FOREIGN / "nes_boxhit.nes", "--labels", FOREIGN / "nes_boxhit.lbl",
                           "--entry", "boxhit", "--scene", scene)
    assert code == 2
    assert err == (f"retro run: --scene {scene}: a scene for the 6510, but {FOREIGN / 'nes_boxhit.nes'} is a program "
                   f"for the 2A03\n")
