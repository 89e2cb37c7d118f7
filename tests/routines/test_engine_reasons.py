"""What `retro check` says about the engine with a scene: an interrupt handler's RTI is its return
(the reason names what really keeps it on Machine), and "each lane stalled as on the scene" only
when a call did stall."""

from __future__ import annotations

import json
from pathlib import Path

from retro.cli import main

ROOT = Path(__file__).resolve().parents[2]
FAST = ["--jobs", "1", "--random", "0", "--no-search"]
NES_SCENE = 'chip = "nes"\n[[oam]]\ny = 100\ntile = 0\nx = 100\n'


def _handler(tmp_path: Path, body: str) -> tuple[str, str]:
    """An NMI handler's spec (A in, A out, A kept) and a NES scene with the NMI off."""
    (tmp_path / "nmi.s").write_text(f"        .org $c000\nnmi:    pha\n{body}        pla\n        rti\n")
    (tmp_path / "nmi_ref.py").write_text("def f(a):\n    return a\n")
    (tmp_path / "nmi.toml").write_text(
        '[program]\nfile = "nmi.s"\nentry = "nmi"\ncpu = "2a03"\ninterrupt = "nmi"\n[inputs]\na = "A"\n'
        '[outputs]\nr = "A"\n[reference]\nfunction = "nmi_ref.py:f"\n[cases]\nexhaustive = ["a"]\n')
    (tmp_path / "scene.toml").write_text(NES_SCENE)
    return str(tmp_path / "nmi.toml"), str(tmp_path / "scene.toml")


def _check(capsys, *args) -> tuple[int, str]:
    code = main(["check", *map(str, args), *FAST])
    out, err = capsys.readouterr()
    return code, out + err


def _engine_line(text: str) -> str:
    return next(line for line in text.splitlines() if "engine with the scene" in line)


def test_an_nmi_handler_ending_in_rti_is_kept_on_machine_by_its_oam_dma(tmp_path, capsys):
    spec, scene = _handler(tmp_path, "        lda #$02\n        sta $4014\n")
    code, out = _check(capsys, spec, "--scene", scene, "--in-nmi")
    assert code == 0, out
    # the handler is followed through to its RTI: what keeps it on Machine is its write to $4014
    assert _engine_line(out) == "  engine with the scene: Machine: the access at $C003 reaches a chip register"


def test_a_chip_free_nmi_handler_runs_on_the_batched_core_as_on_machine(tmp_path, capsys):
    spec, scene = _handler(tmp_path, "        lda #$01\n        sta $10\n")
    code, out = _check(capsys, spec, "--scene", scene, "--in-nmi", "--engine", "batch", "--json")
    assert code == 0, out
    (batch,) = json.loads(out)
    code, out = _check(capsys, spec, "--scene", scene, "--in-nmi", "--engine", "scalar", "--json")
    (scalar,) = json.loads(out)
    assert batch["engine"] == "batch" and scalar["engine"] == "scalar"
    assert batch["engine_reason"] == "the routine touches no chip register (checked from its code)"
    # 7 (the NMI sequence) + PHA 3 + LDA # 2 + STA zp 3 + PLA 4 + RTI 6, nothing stolen
    assert (batch["min"], batch["max"], batch["mismatches"]) == (scalar["min"], scalar["max"], 0) == (25, 25, 0)
    code, out = _check(capsys, spec, "--scene", scene, "--in-nmi", "--engine", "batch")
    line = _engine_line(out)
    assert line.startswith("  engine with the scene: the batched core, no call stalled on the scene: ")
    assert "each lane stalled" not in out


def test_each_lane_stalled_is_said_where_the_scene_stalled_a_call(capsys):
    scene = ROOT / "examples" / "vic_two_balls.toml"
    # raster line 51 is a Bad Line (DEN on, YSCROLL 3): calls entered at its cycle 1 stall
    code, out = _check(capsys, "aabb8", "--scene", scene, "--at-line", "51", "--engine", "batch")
    assert code == 0, out
    assert _engine_line(out).startswith("  engine with the scene: the batched core, each lane stalled as on the scene: ")
    # line 250 is in the lower border: no Bad Line, and the scene's sprites are elsewhere
    code, out = _check(capsys, "aabb8", "--scene", scene, "--at-line", "250", "--engine", "batch")
    assert code == 0, out
    assert _engine_line(out).startswith("  engine with the scene: the batched core, no call stalled on the scene: ")


def test_progress_past_the_planned_cases_says_the_search_found_them(monkeypatch):
    from types import SimpleNamespace

    from retro.analysis.check import run as check_run
    from retro.analysis.check.tally import Tally

    monkeypatch.setattr(check_run, "PROGRESS_SECONDS", -1.0)  # every block reported
    shown: list[str] = []
    report = check_run._reporter(SimpleNamespace(name="r"), Tally(), 10, False, shown.append)
    report(Tally(cases=10))
    report(Tally(cases=3))  # the search's cases, checked after the planned ones
    assert shown == ["check r: 10/10 cases", "check r: 13 cases (10 planned, plus the search)"]
