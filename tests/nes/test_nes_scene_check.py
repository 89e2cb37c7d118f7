"""NES scenes in `retro check`, `cycles`, `run` and `profile` (issue 25, part 4): every call entered at
a scanline and dot, or as the NMI handler, with the vblank budget and OAM DMA counted.

The expected numbers are worked out by hand from the NTSC frame (nesdev wiki "PPU frame timing":
341 dots a scanline, 262 scanlines, the vblank flag set at scanline 241 dot 1, rendering from the
pre-render scanline 261; "Cycle reference chart": 3 dots a CPU cycle; "PPU registers", OAMDMA:
513 cycles, +1 on an odd CPU cycle) and the convention of retro.chips.ppu.clock (CPU cycle c of
the frame begins at dot 3c; a read in cycle c sees events at dots <= 3c; odd/even counted from the
frame's first cycle).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPRITE0_SCENE = ROOT / "examples" / "nes_sprite0.toml"
FAST = ["--jobs", "1", "--random", "0", "--no-search"]


def _spec(tmp_path: Path, name: str, source: str, *, inputs: str = 'a = "A"', outputs: str = 'r = "A"',
          reference: str = "def f(a):\n    return a\n", extra: str = "") -> str:
    (tmp_path / f"{name}.s").write_text(source)
    (tmp_path / f"{name}_ref.py").write_text(reference)
    (tmp_path / f"{name}.toml").write_text(
        f'[program]\nfile = "{name}.s"\nentry = "{name}"\ncpu = "2a03"\n{extra}[inputs]\n{inputs}\n'
        f'[outputs]\n{outputs}\n[reference]\nfunction = "{name}_ref.py:f"\n[cases]\nexhaustive = ["a"]\n')
    return str(tmp_path / f"{name}.toml")


def _scene(tmp_path: Path, ctrl: int = 0) -> str:
    path = tmp_path / f"scene_{ctrl}.toml"
    path.write_text(f'chip = "nes"\n[ppu]\nctrl = {ctrl}\n[[oam]]\ny = 100\ntile = 0\nx = 100\n')
    return str(path)


def _json(capsys, command: str, *args) -> tuple[int, list[dict]]:
    code = main([command, *args, "--json"])
    out, err = capsys.readouterr()
    return code, (json.loads(out) if out.strip() else err)


NMI_HANDLER = """        .org $c000
nmi:    pha
        lda #$02
        sta $4014
        pla
        rti
"""


def test_an_nmi_handlers_vblank_budget_is_the_ntsc_vblank_less_the_flags_dot(tmp_path, capsys):
    # Entered as "nmi" the call counts the 7-cycle interrupt sequence, begun at the vblank flag:
    # scanline 241 dot 1, CPU cycle 82,182 / 3 = 27,394 of the frame. Up to the pre-render line
    # (261 x 341 = dot 89,001): 20 scanlines x 341 dots less the flag's dot 0 = 6,819 dots = 2,273 cycles.
    # The handler: sequence 7 (cycles 0-6), PHA 3 (7-9), LDA # 2 (10-11), STA abs 4 (12-15, the write in
    # 15: frame cycle 27,409, odd: DMA 514), PLA 4, RTI 6: 26 + 514 = 540 cycles; 2,273 - 540 = 1,733 left.
    spec = _spec(tmp_path, "nmi", NMI_HANDLER, extra='interrupt = "nmi"\n')
    code, (record,) = _json(capsys, "check", spec, "--scene", _scene(tmp_path), "--in-nmi", *FAST)
    assert code == 0 and record["mismatches"] == 0
    assert (record["min"], record["max"]) == (540, 540)
    assert record["vblank"] == {"budget": 2273, "best_left": 1733, "worst_left": 1733, "oam_dma_max": 514}
    scene = record["raster"]["scene"]
    assert (scene["start_line"], scene["start_dot"], scene["in_nmi"]) == (241, 1, True)
    # returns at frame cycle 27,394 + 540 = 27,934: dot 83,802 = scanline 245 (83,545) dot 257
    assert (scene["slowest_end_line"], scene["slowest_end_dot"], scene["frames_crossed"]) == (245, 257, 0)
    assert scene["stolen_max"] == 514 and record["cpu_max"] == 26
    # `retro cycles` shows the same run; with the NMI enabled ($2000 bit 7) the handler is that NMI:
    # its edge is taken, no second one comes during the call
    code, (row,) = _json(capsys, "cycles", spec, "--scene", _scene(tmp_path, ctrl=0x80), "--in-nmi", *FAST)
    assert code == 0 and row["vblank"]["budget"] == 2273 and row["max"] == row["min"] == 540


def test_on_pal_the_vblank_is_70_scanlines_at_3_2_dots_a_cycle(tmp_path, capsys):
    # PAL (2C07): 312 scanlines, pre-render 311, 3.2 dots a CPU cycle. The sequence begins at the first
    # cycle at or after the handler's (82,182 + 7 x 3.2 = 82,204.4 dots -> cycle 25,689) less 7: 25,682,
    # dot floor(82,182.4) = 82,182, scanline 241 dot 1. To dot 311 x 341 = 106,051: 23,869 dots / 3.2 =
    # 7,459 cycles. The write in call cycle 15 is frame cycle 25,697, odd: 514; 540 in all, 6,919 left.
    spec = _spec(tmp_path, "nmi", NMI_HANDLER, extra='interrupt = "nmi"\n')
    scene = tmp_path / "pal.toml"
    scene.write_text('chip = "nes"\nvideo = "pal"\n[[oam]]\ny = 100\ntile = 0\nx = 100\n')
    code, (record,) = _json(capsys, "cycles", spec, "--scene", str(scene), "--in-nmi", *FAST)
    assert code == 0 and record["vblank"] == {"budget": 7459, "best_left": 6919, "worst_left": 6919,
                                              "oam_dma_max": 514}
    assert (record["raster"]["scene"]["start_line"], record["raster"]["scene"]["start_dot"]) == (241, 1)


def test_a_handler_called_by_jsr_in_the_nmi_has_the_sequences_cycles_less(tmp_path, capsys):
    # Called as by JSR (as `retro run --in-nmi` does) its first cycle follows the sequence: 27,401,
    # scanline 241 dot 22; 89,001 - 82,203 = 6,798 dots = 2,266 cycles. CLC/ADC #1/RTS: 2 + 2 + 6 = 10.
    spec = _spec(tmp_path, "inc", "        .org $c000\ninc:    clc\n        adc #1\n        rts\n",
                 reference="def f(a):\n    return (a + 1) & 0xFF\n")
    code, (record,) = _json(capsys, "check", spec, "--scene", _scene(tmp_path), "--in-nmi", *FAST)
    assert code == 0 and record["vblank"] == {"budget": 2266, "best_left": 2256, "worst_left": 2256, "oam_dma_max": 0}
    assert (record["raster"]["scene"]["start_line"], record["raster"]["scene"]["start_dot"]) == (241, 22)


DMA = """        .org $c000
dma:    lda #$02
        sta $4014
        rts
"""


@pytest.mark.parametrize("dot, dma", [(1, 513), (4, 514)])
def test_oam_dma_costs_513_on_an_even_cycle_and_514_on_an_odd_one(tmp_path, capsys, dot, dma):
    # Scanline 10 dot 1 is dot 3,411: the first cycle beginning there is 1,137 (dot 3,411); dot 4 (3,414)
    # is cycle 1,138. LDA # takes cycles 0-1, STA abs 2-5 with its write in 5: frame cycle 1,142 (even,
    # 513) or 1,143 (odd, 514). The call: 2 + 4 + DMA + 6 (RTS).
    spec = _spec(tmp_path, "dma", DMA, reference="def f(a):\n    return 2\n")
    code, (record,) = _json(capsys, "check", spec, "--scene", _scene(tmp_path), "--at-line", "10", "--at-dot",
                            str(dot), *FAST)
    assert code == 0 and record["mismatches"] == 0
    assert record["max"] == record["min"] == 12 + dma and record["raster"]["scene"]["stolen_max"] == dma
    assert (record["raster"]["scene"]["start_line"], record["raster"]["scene"]["start_dot"]) == (10, 1 + 3 * (dot > 1))
    assert record["engine"] == "scalar" and "reaches a chip register" in record["engine_reason"]
    # 261 x 341 = 89,001 dots to the pre-render line: from dot 3,411 that is 85,590 / 3 = 28,530 cycles
    assert record["vblank"]["budget"] == (28530 if dot == 1 else 28529)


POLL = """        .org $c000
wait:   bit $2002
        bvc wait
        rts
"""


@pytest.mark.parametrize("where, cycles, end", [
    # Sprite 0 of examples/nes_sprite0.toml (Y 25, X 88, tile 4: row 0 "...33...") first meets the
    # bar's opaque row on scanline 26 at x = 91: the flag is set at dot 92, absolute dot 26 x 341 + 92
    # = 8,958. Entered at scanline 20 (cycle ceil(6,820 / 3) = 2,274, dot 6,822 = scanline 20 dot 2),
    # the loop (BIT abs 4, its read in its last cycle; BVC taken 3) reads in call cycles 3 + 7k: the
    # first read at or past dot 8,958 is k = 102 (frame cycle 2,991, dot 8,973); BVC not taken 2, RTS 6:
    # 717 + 1 + 2 + 6 = 726 cycles, returning at frame cycle 3,000 = dot 9,000 = scanline 26 dot 134.
    (("--at-line", "20"), 726, (26, 134)),
    # entered after the hit (scanline 30) or in vblank the flag is already set (it stays set until the
    # pre-render line): the first read sees it: 4 + 2 + 6 = 12 cycles
    (("--at-line", "30"), 12, (30, 36)),
    (("--in-nmi",), 12, (241, 58)),
])
def test_a_sprite_zero_poll_returns_on_the_hits_scanline(tmp_path, capsys, where, cycles, end):
    spec = _spec(tmp_path, "wait", POLL, inputs='a = { at = "A", values = "0..0" }', outputs='v = "V"',
                 reference="def f(a):\n    return 1\n", extra="")
    (tmp_path / "wait.toml").write_text((tmp_path / "wait.toml").read_text() + "[cycles]\nstatic = false\n")
    code, (record,) = _json(capsys, "check", spec, "--scene", str(SPRITE0_SCENE), *where, *FAST)
    assert code == 0 and record["mismatches"] == 0
    assert record["min"] == record["max"] == cycles
    assert (record["raster"]["scene"]["slowest_end_line"], record["raster"]["scene"]["slowest_end_dot"]) == end
    # `retro run` enters the call at the same place and sees the same
    source = tmp_path / "wait.s"
    code, run = _json(capsys, "run", str(source), "--entry", "wait", "--scene", str(SPRITE0_SCENE), *where)
    assert code == 0 and run["cycles"] == cycles and (run["vblank"]["end_line"], run["vblank"]["end_dot"]) == end


def test_a_routine_touching_no_chip_register_runs_on_the_batched_core_unless_the_nmi_can_come(tmp_path, capsys):
    spec = _spec(tmp_path, "inc", "        .org $c000\ninc:    clc\n        adc #1\n        rts\n",
                 reference="def f(a):\n    return (a + 1) & 0xFF\n")
    code, (record,) = _json(capsys, "check", spec, "--scene", _scene(tmp_path), "--at-line", "100",
                            "--engine", "batch", "--jobs", "1", "--no-search")
    assert code == 0 and record["engine"] == "batch" and record["mismatches"] == 0
    assert record["engine_reason"].startswith("the routine touches no chip register")
    assert record["engine_agreement"]["mismatches"] == 0 and record["engine_agreement"]["cases"] > 0
    # with $2000 bit 7 set the NMI may come in a call as long as the spec's limit: Machine, and why
    code, (record,) = _json(capsys, "check", spec, "--scene", _scene(tmp_path, ctrl=0x80), "--at-line", "100",
                            *FAST)
    assert code == 0 and record["engine"] == "scalar" and "enables the NMI" in record["engine_reason"]
    code = main(["check", spec, "--scene", _scene(tmp_path, ctrl=0x80), "--engine", "batch", *FAST])
    assert code == 2 and "enables the NMI" in capsys.readouterr().err


@pytest.mark.parametrize("args, message", [
    (("--at-cycle", "5"), "--at-cycle: a VIC-II option"),
    (("--at-line", "262"), "the NTSC PPU has scanlines 0-261 and dots 0-340, got scanline 262"),
    (("--at-dot", "341"), "got scanline 0 dot 341"),
    (("--in-nmi", "--at-line", "5"), "--in-nmi enters at the start of vblank: not with --at-line/--at-dot"),
])
def test_bad_nes_entries_are_one_line_errors(tmp_path, capsys, args, message):
    spec = _spec(tmp_path, "inc", "        .org $c000\ninc:    rts\n")
    for command in ("check", "cycles"):
        assert main([command, spec, "--scene", _scene(tmp_path), *args, *FAST]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1


def test_nes_options_need_a_nes_scene(tmp_path, capsys):
    spec = _spec(tmp_path, "inc", "        .org $c000\ninc:    rts\n")
    assert main(["check", spec, "--in-nmi", *FAST]) == 2
    assert "--in-nmi: needs a NES scene" in capsys.readouterr().err
    vic = tmp_path / "vic.toml"
    vic.write_text('chip = "vic-ii"\nvideo = "pal"\n')
    assert main(["cycles", "aabb8", "--scene", str(vic), "--at-dot", "3", *FAST]) == 2
    assert "--at-dot: needs a NES scene; " in capsys.readouterr().err


def test_profile_of_a_specs_cases_on_a_nes_scene_counts_oam_dma(tmp_path, capsys):
    spec = _spec(tmp_path, "dma", DMA, reference="def f(a):\n    return 2\n")
    code = main(["profile", spec, "--scene", _scene(tmp_path), "--at-line", "10", "--at-dot", "4", "--cases", "3",
                 "--json"])
    report = json.loads(capsys.readouterr().out)
    (routine,) = report["routines"]
    assert code == 0 and routine["calls"] == 3 and routine["max"] == routine["min"] == 12 + 514
    assert report["stolen"] == 3 * 514
    # each call from scanline 10: 526 cycles x 3 dots = 1,578 dots, scanlines 10-14
    assert routine["lines"] == [[10, 14]]


def test_profile_of_a_specs_cases_counts_each_calls_lines_from_its_own_start(capsys):
    # the same rule on a C64 scene: 50 calls of aabb8 (20-34 cycles, none stolen), each restarted at
    # raster line 250 cycle 1, all end within that 63-cycle line (the beam was once read from the first
    # call's start: the later calls' lines ran on from it, 0-20)
    code = main(["profile", "aabb8", "--cases", "50", "--scene", str(ROOT / "examples" / "vic_two_balls.toml"),
                 "--at-line", "250", "--json"])
    (routine,) = json.loads(capsys.readouterr().out)["routines"]
    assert code == 0 and routine["calls"] == 50 and routine["max"] <= 34 and routine["stolen"] == 0
    assert routine["lines"] == [[250, 250]]
