"""Inputs that used to break `retro asm` / `retro run`: each gives one line and the right exit status,
never a traceback, a hang or a half-written output."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from retro import fileio
from retro.cli import main
from retro.errors import InputError

OK_SOURCE = "        .org $c000\nentry:  lda #1\n        rts\n"


def _one_line(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


@pytest.fixture
def source(tmp_path) -> Path:
    path = tmp_path / "ok.s"
    path.write_text(OK_SOURCE)
    return path


def test_asm_never_writes_over_its_source(source, capsys):
    assert main(["asm", str(source), "-o", str(source)]) == 2
    assert "is an input of this command" in _one_line(capsys)
    assert source.read_text() == OK_SOURCE


def test_asm_writes_all_outputs_or_none(source, tmp_path, capsys):
    prg = tmp_path / "ok.prg"
    assert main(["asm", str(source), "-o", str(prg), "--labels", str(tmp_path)]) == 2
    assert "is a folder" in _one_line(capsys)
    assert not prg.exists() and not list(tmp_path.glob(".*.tmp"))


def test_an_output_that_is_a_device_is_refused(source, capsys):
    assert main(["asm", str(source), "-o", os.devnull]) == 2
    assert "not a regular file" in _one_line(capsys)


@pytest.mark.parametrize("text, message", [
    ("        lda #1/0\n", "the assembler failed on this source: ZeroDivisionError"),
    ("        .org $10000\n        lda #1\n", "the code starts at $10000, above $FFFF"),
    ('        .include "self.s"\n', "the assembler recursed too deeply"),
])
def test_ophis_crashes_are_one_line(tmp_path, capsys, text, message):
    path = tmp_path / "self.s"
    path.write_text(text)
    assert main(["asm", str(path)]) == 2
    assert message in _one_line(capsys)


def test_a_fifo_source_is_read_once(tmp_path, capsys):
    fifo = tmp_path / "pipe.s"
    os.mkfifo(fifo)
    writer = threading.Thread(target=lambda: fifo.write_text(OK_SOURCE))
    writer.start()
    assert main(["asm", str(fifo), "-o", str(tmp_path / "pipe.prg")]) == 0
    writer.join(timeout=10)
    assert (tmp_path / "pipe.prg").read_bytes() == bytes([0x00, 0xC0, 0xA9, 0x01, 0x60])


def test_an_endless_file_is_refused_not_read(capsys):
    assert main(["run", "/dev/zero", "--entry", "0"]) == 2
    assert "larger than" in _one_line(capsys)


def test_numbers_of_thousands_of_digits(source, capsys):
    assert main(["run", str(source), "--entry", "9" * 5000]) == 2
    assert "not a number" in _one_line(capsys)


def test_budget_and_trace_are_bounded(tmp_path, capsys):
    spin = tmp_path / "spin.s"
    spin.write_text("        .org $c000\nspin:   jmp spin\n")
    assert main(["run", str(spin), "--entry", "spin", "--budget", str(10 ** 12)]) == 2
    assert "--budget" in _one_line(capsys)
    assert main(["run", str(spin), "--entry", "spin", "--trace", "--budget", "10000000"]) == 1
    assert "the trace is longer than 200,000 instructions" in _one_line(capsys)


def test_an_interrupted_write_leaves_no_temp_file(tmp_path, monkeypatch):
    def interrupted(*args):
        raise KeyboardInterrupt
    monkeypatch.setattr(fileio.os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        fileio.write_all_atomic({tmp_path / "a.bin": b"1", tmp_path / "b.bin": b"2"})
    assert list(tmp_path.iterdir()) == []


def test_a_symlink_is_refused_not_written_through(tmp_path):
    real = tmp_path / "real.bin"
    real.write_bytes(b"old")
    link = tmp_path / "link.bin"
    link.symlink_to(real)
    with pytest.raises(InputError, match="symbolic link"):
        fileio.write_atomic(link, b"new")
    assert link.is_symlink() and real.read_bytes() == b"old"
    with pytest.raises(InputError, match="same file"):
        fileio.write_all_atomic({tmp_path / "a.bin": b"1", tmp_path / "x" / ".." / "a.bin": b"2"})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.bin", "real.bin"]


def test_ctrl_c_in_a_check_exits_130_without_a_traceback(tmp_path):
    spin = tmp_path / "spin.s"
    spin.write_text("        .org $c000\nspin:   jmp spin\n")
    (tmp_path / "ref.py").write_text("def spin(a):\n    return a\n")
    (tmp_path / "spin.toml").write_text('[program]\nfile = "spin.s"\nentry = "spin"\n[inputs]\na = "A"\n'
                                        '[outputs]\nr = "A"\n[reference]\nfunction = "ref.py:spin"\n'
                                        '[cycles]\nstatic = false\nlimit = 90000000\n[cases]\nrandom = 100\n')
    process = subprocess.Popen([sys.executable, "-m", "retro", "check", str(tmp_path / "spin.toml"), "--jobs", "2"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    import signal
    import time

    time.sleep(3)
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=60)
    assert process.returncode == 130 and "Traceback" not in err and err.strip().endswith("interrupted"), err


def test_a_folder_given_as_a_sprite_file_says_so(tmp_path, capsys):
    (tmp_path / "ball.spr").mkdir()
    (tmp_path / "scene.toml").write_text('chip = "vic-ii"\nvideo = "pal"\n[registers]\n"$d015" = 1\n'
                                         '[[sprite]]\nindex = 0\nx = 100\ny = 100\nfile = "ball.spr"\n')
    assert main(["vic", str(tmp_path / "scene.toml")]) == 2
    assert "is a folder, not a file" in _one_line(capsys)
