"""`retro run --entry E --scene S` and `retro profile --entry`/a spec's cases with a scene: the scene
file is read once per run, and the errors about it come in the same order with the same text as when
each check read the file again (the scene's own options first, then its CPU against the program's,
then --cpu)."""

from __future__ import annotations

from pathlib import Path

import pytest

import retro.scenes
from retro.cli import main
from retro.paths import EXAMPLES_DIR

FOREIGN = Path(__file__).resolve().parent.parent / "data" / "foreign"
VIC_SCENE = EXAMPLES_DIR / "vic_two_balls.toml"
NES_PROGRAM = FOREIGN / "nes_boxhit.nes"
NES_LABELS = FOREIGN / "nes_boxhit.lbl"


def _cli(capsys, *argv) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def scene_reads(monkeypatch) -> list[str]:
    """Every scene file `retro.scenes.load_scene` reads in the test, in order."""
    reads: list[str] = []
    real = retro.scenes.load_scene

    def counting(path):
        reads.append(str(path))
        return real(path)

    monkeypatch.setattr(retro.scenes, "load_scene", counting)
    return reads


def test_the_scenes_cpu_against_the_programs_is_one_exact_line(capsys):
    code, _, err = _cli(capsys, "run", NES_PROGRAM, "--labels", NES_LABELS, "--entry", "boxhit", "--scene", VIC_SCENE)
    assert code == 2
    assert err == (f"retro run: --scene {VIC_SCENE}: a scene for the 6510, but {NES_PROGRAM} is a program "
                   f"for the 2A03\n")


def test_the_scenes_own_options_are_checked_before_its_cpu(capsys):
    code, _, err = _cli(capsys, "run", NES_PROGRAM, "--labels", NES_LABELS, "--entry", "boxhit", "--scene", VIC_SCENE,
                        "--at-line", "400")
    assert code == 2
    assert err == ("retro run: --at-line/--at-cycle: the 6569 has lines 0-311 and cycles 1-63, got line 400 "
                   "cycle 1\n")


def test_the_programs_file_is_checked_before_the_scene(capsys, tmp_path):
    missing = tmp_path / "missing.toml"
    code, _, err = _cli(capsys, "run", NES_PROGRAM, "--entry", "boxhit", "--scene", missing)
    assert code == 2 and err.count("\n") == 1 and "has no symbols" in err


def test_the_scene_against_the_program_comes_before_cpu_against_the_scene(capsys):
    # the iNES image is a 2A03 program: its mismatch with the VIC-II scene is named, not --cpu's
    code, _, err = _cli(capsys, "run", NES_PROGRAM, "--labels", NES_LABELS, "--entry", "boxhit", "--scene", VIC_SCENE,
                        "--cpu", "2a03")
    assert code == 2 and "a scene for the 6510, but" in err and err.count("\n") == 1


def test_run_with_a_scene_reads_the_scene_file_once(capsys, scene_reads):
    code, _, err = _cli(capsys, "run", FOREIGN / "acme_boxhit.prg", "--labels", FOREIGN / "acme_boxhit.sym",
                        "--entry", "boxhit", "--scene", VIC_SCENE, "--at-line", "100")
    assert code == 0, err
    assert scene_reads == [str(VIC_SCENE)]


def test_run_in_an_nmi_handler_reads_the_nes_scene_once(capsys, tmp_path, scene_reads):
    source = tmp_path / "nmi.s"
    source.write_text(".org $c000\nnmi:    lda #$02\n        rts\n")
    scene = tmp_path / "s.toml"
    scene.write_text('chip = "nes"\n[[oam]]\ny = 100\ntile = 0\nx = 100\n')
    code, _, err = _cli(capsys, "run", source, "--entry", "nmi", "--scene", scene, "--in-nmi")
    assert code == 0, err
    assert scene_reads == [str(scene)]


def test_profile_of_a_call_reads_the_scene_file_once(capsys, scene_reads):
    code, _, err = _cli(capsys, "profile", FOREIGN / "acme_boxhit.prg", "--labels", FOREIGN / "acme_boxhit.sym",
                        "--entry", "boxhit", "--scene", VIC_SCENE, "--json")
    assert code == 0, err
    assert scene_reads == [str(VIC_SCENE)]


def test_profile_of_a_specs_cases_reads_the_scene_file_once(capsys, scene_reads):
    code, _, err = _cli(capsys, "profile", "aabb8", "--cases", "3", "--scene", VIC_SCENE, "--json")
    assert code == 0, err
    assert scene_reads == [str(VIC_SCENE)]
