"""`retro asm`, `retro run` and `retro demo`: contracts (flags, JSON keys), exit codes, one-line errors."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from retro.cli import main

ROUTINE = """\
.org $c000
double: asl          ; A = 2 * A
        sta result
        rts
spin:   jmp spin
stop:   brk          ; $C008: ASL 1 byte, STA 3, RTS 1, JMP 3
result: .byte 0
"""
# Hand count: ASL A 2 + STA abs 4 + RTS 6.
DOUBLE_CYCLES = 2 + 4 + 6


@pytest.fixture
def source(tmp_path: Path) -> Path:
    path = tmp_path / "routine.s"
    path.write_text(ROUTINE)
    return path


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exit_:  # argparse usage errors
        code = exit_.code
    out, err = capsys.readouterr()
    return code, out, err


def test_run_json_has_exactly_the_contract_keys_and_types(capsys, source):
    code, out, err = run_cli(capsys, "run", source, "--entry", "double", "--a", "$21",
                             "--peek", "result", "--peek", "$c000:2", "--json")
    assert (code, err) == (0, "")
    report = json.loads(out)
    assert list(report) == ["cycles", "instructions", "a", "x", "y", "s", "p", "peek"]
    assert all(type(report[k]) is int for k in ("cycles", "instructions", "a", "x", "y", "s", "p"))
    assert report["cycles"] == DOUBLE_CYCLES and report["instructions"] == 3
    assert (report["a"], report["s"]) == (0x42, 0xFF)
    assert report["peek"] == {"result": [0x42], "$c000": [0x0A, 0x8D]}  # keys: TARGET as given, without :N


def test_run_sets_memory_and_accepts_every_number_notation(capsys, source):
    code, out, _ = run_cli(capsys, "run", source, "--entry", "0xc000", "--a", "%11", "--x", "7", "--y", "$ff",
                           "--set", "result=9", "--set", "$c100=1,2,0x03", "--peek", "$c100:3", "--json")
    report = json.loads(out)
    assert code == 0 and (report["a"], report["x"], report["y"]) == (6, 7, 0xFF)
    assert report["peek"] == {"$c100": [1, 2, 3]}


def test_run_text_output_says_the_jsr_is_not_counted(capsys, source):
    code, out, _ = run_cli(capsys, "run", source, "--entry", "double", "--a", "1", "--trace")
    assert code == 0
    assert f"{DOUBLE_CYCLES} cycles, 3 instructions" in out and "JSR" in out
    assert "ASL" in out and "STA" in out


@pytest.mark.parametrize("args, code, needle", [
    (["--entry", "spin", "--budget", "500"], 1, "budget"),
    (["--entry", "stop"], 1, "BRK"),
    (["--entry", "nowhere"], 2, "--entry: unknown label 'nowhere'"),
    (["--entry", "double", "--a", "256"], 2, "--a: '256' is out of range"),
    (["--entry", "double", "--x", "ten"], 2, "--x: not a number"),
    (["--entry", "double", "--set", "result=300"], 2, "--set result"),
    (["--entry", "double", "--set", "nolabel=1"], 2, "unknown label 'nolabel'"),
    (["--entry", "double", "--peek", "result:0"], 2, "out of range"),
    (["--entry", "double", "--budget", "0"], 2, "--budget"),
    (["--entry", "double", "--labels", "x.lbl"], 2, "a symbol file (--labels) goes with a .prg"),
])
def test_run_failures_exit_1_or_2_with_one_line(capsys, source, args, code, needle):
    got, out, err = run_cli(capsys, "run", source, *args)
    assert got == code
    assert err.count("\n") == 1 and err.startswith("retro run: ") and needle in err
    assert "Traceback" not in err and out == ""


def test_usage_errors_exit_2(capsys, source):
    assert run_cli(capsys, "run", source)[0] == 2  # --entry missing
    assert run_cli(capsys, "frobnicate")[0] == 2
    code, _, err = run_cli(capsys, "run", source.parent / "absent.s", "--entry", "x")
    assert code == 2 and "not found" in err and err.count("\n") == 1


def test_control_characters_in_names_cannot_split_or_colour_the_error_line(capsys, tmp_path):
    # A file name (or TOML key) with a newline or an ANSI escape is echoed in the error: it must
    # stay one line on stderr and must not reach the terminal as a control sequence.
    for name in ("two\nlines.s", "\x1b[31mred.s", "bell\a\r.s"):
        code, out, err = run_cli(capsys, "asm", tmp_path / name)
        assert code == 2 and out == ""
        assert err.count("\n") == 1 and err.endswith("\n")
        assert not any(ord(c) < 0x20 or c == "\x7f" for c in err[:-1]), repr(err)
        assert "source file not found" in err


def test_asm_writes_prg_labels_and_listing_that_run_reads_back(capsys, source, tmp_path):
    prg, lbl, lst = tmp_path / "out.prg", tmp_path / "out.lbl", tmp_path / "out.lst"
    code, out, _ = run_cli(capsys, "asm", source, "-o", prg, "--labels", lbl, "--list", lst)
    assert code == 0 and str(prg) in out
    data = prg.read_bytes()
    assert data[:3] == bytes([0x00, 0xC0, 0x0A])  # load address $C000, then ASL A
    assert "al C:c000 .double" in lbl.read_text().splitlines()
    assert "ASL" in lst.read_text()
    code, out, _ = run_cli(capsys, "run", prg, "--labels", lbl, "--entry", "double", "--a", "5", "--peek", "result",
                           "--json")
    assert code == 0 and json.loads(out)["peek"] == {"result": [10]}
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp files left


def test_asm_default_output_is_beside_the_source(capsys, source):
    assert run_cli(capsys, "asm", source)[0] == 0
    assert source.with_suffix(".prg").read_bytes()[:2] == bytes([0x00, 0xC0])


def test_asm_syntax_error_is_file_line_message_and_exit_2_and_leaves_old_output(capsys, tmp_path):
    bad = tmp_path / "bad.s"
    bad.write_text(".org $c000\nlda #1\nlda (\n")
    out_prg = tmp_path / "bad.prg"
    out_prg.write_bytes(b"old")
    code, _, err = run_cli(capsys, "asm", bad, "-o", out_prg)
    assert code == 2 and err.startswith(f"retro asm: {bad}:3: ") and err.count("\n") == 1
    assert out_prg.read_bytes() == b"old"


def test_asm_output_is_replaced_in_one_rename(capsys, source, tmp_path, monkeypatch):
    """write_atomic writes a temp file beside the target and renames it over; a failed rename
    leaves the old file whole and no temp file behind."""
    target = tmp_path / "atomic.prg"
    target.write_bytes(b"previous")
    renames = []
    real_replace = os.replace

    def failing_replace(src, dst):
        renames.append((Path(src).parent, Path(dst)))
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", failing_replace)
    code, _, err = run_cli(capsys, "asm", source, "-o", target)
    assert code == 2 and "cannot write" in err and str(target) in err
    assert [r for r in renames if r[1].name != "assembled" and r[0].name != "assembled"] == [(tmp_path, target)]
    # (the assembled program's rename into the disk cache failed too: no error, and no file left there)
    assert all(p.suffix == ".json" for p in (Path(os.environ["RETRO_CACHE"]) / "assembled").iterdir())
    assert target.read_bytes() == b"previous"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["atomic.prg", "routine.s"]
    monkeypatch.setattr(os, "replace", real_replace)
    assert run_cli(capsys, "asm", source, "-o", target)[0] == 0
    assert target.read_bytes()[:2] == bytes([0x00, 0xC0])
    assert oct(target.stat().st_mode & 0o777) != oct(0o600)  # not left private like a mkstemp file


def test_demo_assembles_runs_and_names_its_folder(capsys, tmp_path, monkeypatch):
    from retro import workers

    def no_cluster(*args):  # Dask is imported only to start a cluster (retro/workers.py)
        raise AssertionError("retro demo started a Dask cluster")
    monkeypatch.setattr(workers, "_preload", no_cluster)
    monkeypatch.setattr(workers, "_client", no_cluster)
    code, out, err = run_cli(capsys, "demo", "--out", tmp_path / "demo")
    assert code == 0, err
    # demo_sum(X=8) adds 200+100+50+25+12+6+3+1 = 397: one carry, so 11 + 12*8 + 3 cycles.
    assert "sum 397" in out and "110 cycles" in out
    assert str((tmp_path / "demo").resolve()) in out.splitlines()[-1]
    assert (tmp_path / "demo" / "demo_sum.prg").exists()


def test_errors_from_the_installed_script_are_one_line_without_traceback(source):
    done = subprocess.run([sys.executable, "-m", "retro", "run", str(source), "--entry", "stop"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 1
    assert done.stderr.count("\n") == 1 and "BRK (opcode $00) at $C008" in done.stderr


def test_commands_with_output_folders_fail_fast_with_one_line(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    for command in (["demo", "--out"], ["chart", "--reduced", "--out"], ["stability", "--reduced", "--out"]):
        done = subprocess.run([sys.executable, "-m", "retro", *command, str(blocker / "sub")],
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 2, command
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and "cannot create output folder" in lines[0], done.stderr


def test_run_refuses_trace_with_json(capsys):
    from retro.cli import main

    source = str(Path(__file__).resolve().parent.parent / "asm" / "demo_sum.s")
    with pytest.raises(SystemExit) as stopped:
        main(["run", source, "--entry", "demo_sum", "--trace", "--json"])
    assert stopped.value.code == 2
    assert "not allowed with" in capsys.readouterr().err


@pytest.mark.parametrize("option", [["--set", "$ffff=7,9"], ["--peek", "$ffff:3"]])
def test_set_and_peek_never_wrap_past_ffff(capsys, option):
    from retro.cli import main

    source = str(Path(__file__).resolve().parent.parent / "asm" / "demo_sum.s")
    assert main(["run", source, "--entry", "demo_sum", *option]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run past $FFFF" in err


def test_output_folder_that_is_a_file(tmp_path):
    from retro.errors import InputError
    from retro.fileio import output_folder

    blocker = tmp_path / "afile"
    blocker.write_text("x")
    with pytest.raises(InputError, match="is a file, not a folder"):
        output_folder(blocker)


def test_a_check_on_the_batched_core_does_not_import_numba():
    """`retro check --engine batch` (and auto below the compiled engine's threshold) never loads numba
    (the compiled engine's 0.2 s of start-up), in the text report and the JSON alike."""
    script = ("import sys; from retro.cli import main; "
              "code = main(['check', 'mul8', '--random', '50', '--no-search', '--jobs', '1', '--engine', 'batch']); "
              "code += main(['check', 'mul8', '--random', '50', '--no-search', '--jobs', '1', '--engine', 'batch', "
              "'--json']); "
              "print(code, sorted(m for m in sys.modules if m.startswith('numba')))")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])})
    code, modules = done.stdout.strip().splitlines()[-1].split(" ", 1)
    assert code == "0", done.stderr
    assert modules == "[]", modules
