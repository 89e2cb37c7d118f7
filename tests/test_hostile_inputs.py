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
    ("        .org $10000\n        lda #1\n", "self.s:2: code or data at $10000, past $FFFF"),
    ("        .org $c000\n        nop\n        .org $fffe\n        lda $1234\n", "self.s:4: code or data at $10000"),
    ("; nothing but a comment\n", "self.s: no code or data: the source assembles to nothing"),
    ('        .org $c000\n        .incbin "/dev/zero"\n', "self.s:2: /dev/zero: is a device, not a regular file"),
    ('        .include "self.s"\n', "the assembler recursed too deeply"),
])
def test_ophis_crashes_are_one_line(tmp_path, capsys, text, message):
    path = tmp_path / "self.s"
    path.write_text(text)
    assert main(["asm", str(path)]) == 2
    assert message in _one_line(capsys)


def test_a_fifo_is_refused_by_its_kind_without_waiting_for_a_writer(tmp_path, capsys):
    fifo = tmp_path / "pipe.s"
    os.mkfifo(fifo)  # no writer: opening it would block for ever
    assert main(["asm", str(fifo), "-o", str(tmp_path / "pipe.prg")]) == 2
    assert _one_line(capsys).rstrip().endswith("pipe.s: source file is a FIFO (a named pipe), not a regular file")
    assert not (tmp_path / "pipe.prg").exists()


def test_an_endless_file_is_refused_not_read(capsys):
    assert main(["run", "/dev/zero", "--entry", "0"]) == 2
    assert _one_line(capsys).rstrip().endswith("/dev/zero: program file is a device, not a regular file")


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


def test_sizes_are_checked_before_reading(tmp_path, capsys):
    huge = tmp_path / "huge.s"
    with open(huge, "wb") as stream:
        stream.truncate(18_000_000)  # sparse: costs no disk, and would cost 2 GB inside Ophis
    assert main(["asm", str(huge)]) == 2
    assert "huge.s: source file is 18000000 bytes; the most read is 2 MiB" in _one_line(capsys)


def test_incbin_and_include_are_bounded_at_the_line_that_asks(tmp_path, capsys):
    (tmp_path / "big.bin").write_bytes(bytes(range(256)) * 400)  # 102,400 bytes: more than 64 KiB
    with open(tmp_path / "big.inc", "wb") as stream:
        stream.truncate(3 << 20)
    cases = {
        '.org $1000\n.incbin "big.bin"\n': "s.s:2: " + str(tmp_path / "big.bin") + ": 102400 bytes to include, more than the 65536",
        '.org $1000\nnop\n.include "big.inc"\n': "s.s:3: " + str(tmp_path / "big.inc") + ": the sources of this program total more than 2 MiB",
        '.org $1000\n.incbin "' + str(tmp_path) + '"\n': "s.s:2: " + str(tmp_path) + ": is a folder, not a regular file",
    }
    for text, message in cases.items():
        (tmp_path / "s.s").write_text(text)
        assert main(["asm", str(tmp_path / "s.s")]) == 2
        assert message in _one_line(capsys)
    # a slice of a large file is fine: offset 10, 100 bytes
    (tmp_path / "s.s").write_text('.org $1000\n.incbin "big.bin", 10, 100\n')
    assert main(["asm", str(tmp_path / "s.s"), "-o", str(tmp_path / "s.prg")]) == 0
    assert (tmp_path / "s.prg").read_bytes() == b"\x00\x10" + bytes(range(10, 110))


@pytest.mark.parametrize("text, message", [
    ('[chr]\ntiles = { "1:4" = ' + "9" * 5000 + " }\n", "s.toml:2: 1:4: an integer of 5000 digits"),
    ('"$d011" = ' + "9" * 5000 + "\n", "s.toml:1: $d011: an integer of 5000 digits"),
    ("a = 1\nb.c = -" + "7" * 4400 + "\n", "s.toml:2: b.c: an integer of 4400 digits"),
])
def test_a_toml_integer_too_long_for_python_names_its_line_and_key(text, message):
    from retro.errors import InputError
    from retro.fileio import parse_toml

    with pytest.raises(InputError) as error:
        parse_toml(text.encode(), "s.toml")
    assert str(error.value).startswith(message)


def test_read_bytes_refuses_by_kind_and_size_without_opening(tmp_path, monkeypatch):
    import builtins
    import socket

    from retro.errors import InputError
    from retro.fileio import read_bytes

    big = tmp_path / "big.bin"
    with open(big, "wb") as stream:
        stream.truncate(100)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    listener = socket.socket(socket.AF_UNIX)
    listener.bind(str(tmp_path / "sock"))

    def no_open(*args, **kwargs):
        raise AssertionError("opened")

    monkeypatch.setattr(builtins, "open", no_open)
    for path, message in ((big, "big.bin: sprite file is 100 bytes; the most read is 99 bytes"),
                          (fifo, "pipe: sprite file is a FIFO (a named pipe), not a regular file"),
                          (tmp_path / "sock", "sock: sprite file is a socket, not a regular file"),
                          (tmp_path, "sprite file is a folder, not a file"),
                          ("/dev/null", "/dev/null: sprite file is a device, not a regular file")):
        with pytest.raises(InputError) as error:
            read_bytes(path, "sprite file", limit=99)
        assert message in str(error.value)
    listener.close()
    monkeypatch.undo()
    assert read_bytes(big, limit=100) == bytes(100)
