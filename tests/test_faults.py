"""Faults while a command writes (docs/files.md): a stop signal inside the write window, Ctrl-C
during the imports, a full disk, two commands writing the same outputs at once. After each: one
line on stderr, the exit code of the fault, and no temp file nor partial set of outputs left.

The write window is reached deterministically: the child process replaces retro.fileio's
`_write_hook` (called once per output, after its temp file exists and before its bytes are written)
with one that announces itself on stderr and waits for the signal the test then sends. The default
run samples the commands and signals; `-m exhaustive` sweeps every command, signal and window."""

from __future__ import annotations

import errno
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from retro.cli import main

ROOT = Path(__file__).resolve().parents[1]
SOURCE = "        .org $c000\nstart:  lda #{value}\n        rts\n"

# Runs in the child: the hook waits inside the write window of output number WINDOW (1-based).
CHILD = textwrap.dedent("""
    import os, sys, time
    import retro.fileio as fileio
    window = int(os.environ["RETRO_TEST_WINDOW"])
    seen = [0]
    def hook(target):
        seen[0] += 1
        if seen[0] == window:
            sys.stderr.write("IN-WINDOW\\n")
            sys.stderr.flush()
            time.sleep(30)
    fileio._write_hook = hook
    from retro.entry import main
    raise SystemExit(main(sys.argv[1:]))
""")


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def command_cases(tmp: Path) -> dict[str, tuple[list[str], int]]:
    """command -> (arguments, how many outputs it writes)."""
    source = tmp / "a.s"
    source.write_text(SOURCE.format(value=1))
    out = tmp / "out"
    return {
        "asm": (["asm", str(source), "-o", str(out / "a.prg"), "--labels", str(out / "a.lbl"),
                 "--list", str(out / "a.lst")], 3),
        "vic": (["vic", str(ROOT / "examples" / "vic_two_balls.toml"), "--png", str(out / "v.png")], 1),
        "nes": (["nes", str(ROOT / "examples" / "nes_sprite0.toml"), "--png", str(out / "n.png")], 1),
        "parry": (["parry", "--frames", "60", "--out", str(out / "parry")], 4),
        "chart": (["chart", "--reduced", "--jobs", "2", "--quiet", "--out", str(out / "chart")], 4),
        "demo": (["demo", "--out", str(out / "demo")], DEMO_OUTPUTS),
    }


DEMO_OUTPUTS = 24  # with the raster interrupt's profile picture (issue 25)
FULL = os.environ.get("RETRO_EXHAUSTIVE") == "1"


def interrupt_in_window(tmp: Path, command: str, window: int, signum: int) -> None:
    """Run the command until it is inside the write window of its output number `window`, send
    `signum`, and check the end: one line, 128 + signum, the folder as it was before."""
    argv, _ = command_cases(tmp)[command]
    out = tmp / "out"
    out.mkdir(exist_ok=True)
    (out / "previous.txt").write_text("a file of the user's\n")
    before = snapshot(tmp)
    child = subprocess.Popen([sys.executable, "-c", CHILD, *argv], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True, env={**os.environ, "RETRO_TEST_WINDOW": str(window),
                                             "PYTHONPATH": str(ROOT)})
    try:
        line = child.stderr.readline()
        assert line == "IN-WINDOW\n", line + child.stderr.read()
        child.send_signal(signum)
        err = child.stderr.read()
        child.wait(timeout=30)
    finally:
        child.kill()
    assert child.returncode == 128 + signum, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.rstrip().endswith("interrupted" if signum == signal.SIGINT else f"stopped by {signal.Signals(signum).name}")
    assert snapshot(tmp) == before  # no temp file, no output of the interrupted command
    assert not [p for p in tmp.rglob("*") if p.name.endswith(".retro-tmp")]


SAMPLE = [("asm", 2, signal.SIGINT), ("asm", 3, signal.SIGTERM), ("parry", 3, signal.SIGHUP),
          ("vic", 1, signal.SIGTERM)]


@pytest.mark.parametrize("command, window, signum", SAMPLE, ids=[f"{c}-{w}-{s.name}" for c, w, s in SAMPLE])
def test_a_signal_in_the_write_window_leaves_nothing(tmp_path, command, window, signum):
    interrupt_in_window(tmp_path, command, window, signum)


@pytest.mark.exhaustive
@pytest.mark.skipif(not FULL, reason="set RETRO_EXHAUSTIVE=1 for every command, window and signal (minutes); "
                                     "the default run takes the sample above")
def test_every_signal_in_every_write_window_leaves_nothing(tmp_path):
    probe = tmp_path / "probe"
    probe.mkdir()
    for command, (_, outputs) in command_cases(probe).items():
        windows = (1, outputs // 2, outputs) if command == "demo" else range(1, outputs + 1)
        for window in windows:
            for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
                case = tmp_path / f"{command}-{window}-{signum}"
                case.mkdir()
                interrupt_in_window(case, command, window, signum)


def test_a_stop_whose_exception_python_dropped_still_stops_before_the_commit(tmp_path):
    """Python loses a signal handler's exception raised inside code whose errors C clears (a
    `__getattr__` under PyObject_HasAttr); the stop must still win before anything is committed."""
    dropping = CHILD.replace("import retro.fileio as fileio", textwrap.dedent("""
        import retro.fileio as fileio
        import retro.interrupts as interrupts
        real_raise = interrupts._raise
        def dropped(signum, frame):
            try:
                real_raise(signum, frame)
            except KeyboardInterrupt:
                pass  # as C code that clears errors would
        interrupts._raise = dropped"""))
    source = tmp_path / "a.s"
    source.write_text(SOURCE.format(value=1))
    out = tmp_path / "out"
    child = subprocess.Popen([sys.executable, "-c", dropping, "asm", str(source), "-o", str(out / "a.prg"),
                              "--labels", str(out / "a.lbl")], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True, env={**os.environ, "RETRO_TEST_WINDOW": "1", "PYTHONPATH": str(ROOT)})
    try:
        assert child.stderr.readline() == "IN-WINDOW\n"
        child.send_signal(signal.SIGTERM)
        err = child.stderr.read()
        child.wait(timeout=30)
    finally:
        child.kill()
    assert (child.returncode, err) == (143, "retro asm: stopped by SIGTERM\n")
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a.s"]


def test_ctrl_c_during_the_imports_is_one_line_and_130(tmp_path):
    """SIGINT arrives while retro.cli imports numpy (the child sends it to itself at that import)."""
    child = textwrap.dedent("""
        import builtins, os, signal, sys
        real_import = builtins.__import__
        def importing(name, *args, **kwargs):
            if name == "numpy":
                builtins.__import__ = real_import
                os.kill(os.getpid(), signal.SIGINT)
            return real_import(name, *args, **kwargs)
        builtins.__import__ = importing
        from retro.entry import main
        raise SystemExit(main(["check", "aabb8"]))
    """)
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, timeout=60,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert (done.returncode, done.stderr) == (130, "retro: interrupted\n")


def test_a_full_disk_leaves_no_partial_set(tmp_path, capsys, monkeypatch):
    """ENOSPC on the third file of four: exit 2, one line naming it, none of the four in place, the
    previous outputs whole."""
    import retro.fileio as fileio

    out = tmp_path / "parry"
    assert main(["parry", "--frames", "60", "--out", str(out)]) == 0
    capsys.readouterr()
    before = snapshot(tmp_path)
    writes = []

    def full(target):
        writes.append(target)
        if len(writes) == 3:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(fileio, "_write_hook", full)
    assert main(["parry", "--frames", "90", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "No space left on device" in err and writes[2].name in err, err
    assert snapshot(tmp_path) == before


@pytest.fixture
def tiny_disk(tmp_path):
    """A 64 KiB tmpfs (needs root and mount(2)); skipped, saying why, where it cannot be mounted."""
    mount_point = tmp_path / "tiny"
    mount_point.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mount_point)], capture_output=True,
                          text=True) if shutil.which("mount") else None
    if done is None or done.returncode != 0:
        pytest.skip(f"cannot mount a tiny tmpfs here ({done.stderr.strip() if done else 'no mount command'}): "
                    "test_a_full_disk_leaves_no_partial_set simulates ENOSPC instead")
    try:
        yield mount_point
    finally:
        subprocess.run(["umount", str(mount_point)], check=False)


def test_a_really_full_disk(tiny_disk, capsys):
    (tiny_disk / "kept.txt").write_text("mine\n")
    assert main(["parry", "--out", str(tiny_disk / "parry")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "No space left on device" in err, err
    assert sorted(p.name for p in tiny_disk.rglob("*")) == ["kept.txt"]


# Two writers: both wait in their first write window until the other is there too, then commit
# with renames paced so that, without the folder lock, the second would replace the first one's PRG
# but not its labels.
WRITER = textwrap.dedent("""
    import os, sys, time
    from pathlib import Path
    import retro.fileio as fileio
    barrier = Path(os.environ["RETRO_TEST_BARRIER"])
    def meet(target):
        if not (barrier / sys.argv[2]).exists():
            (barrier / sys.argv[2]).touch()
            deadline = time.monotonic() + 30
            while len(list(barrier.iterdir())) < 2 and time.monotonic() < deadline:
                time.sleep(0.01)
    fileio._write_hook = meet
    real_replace = os.replace
    pauses = [0.1, 0.1, 0.1] if sys.argv[2].endswith("s1.s") else [0.15, 0.01, 0.01]  # so they would cross
    def slow_replace(src, dst):
        time.sleep(pauses.pop(0) if pauses else 0)
        real_replace(src, dst)
    os.replace = slow_replace
    from retro.entry import main
    raise SystemExit(main(sys.argv[1:]))
""")


def test_two_writers_at_once_leave_one_whole_set(tmp_path):
    out = tmp_path / "out"
    sources = []
    for value in (1, 2):
        source = tmp_path / f"s{value}.s"
        source.write_text(SOURCE.format(value=value).replace("start:", f"start{value}:"))
        sources.append(source)
    argv = ["-o", str(out / "a.prg"), "--labels", str(out / "a.lbl"), "--list", str(out / "a.lst")]
    for round in range(1):
        barrier = tmp_path / f"barrier{round}"
        barrier.mkdir()
        writers = [subprocess.Popen([sys.executable, "-c", WRITER, "asm", str(s), *argv], stdout=subprocess.DEVNULL,
                                    stderr=subprocess.PIPE, text=True,
                                    env={**os.environ, "PYTHONPATH": str(ROOT), "RETRO_TEST_BARRIER": str(barrier)})
                   for s in sources]
        for writer in writers:
            assert writer.wait(timeout=60) == 0, writer.stderr.read()
        prg, labels, listing = ((out / n).read_bytes() for n in ("a.prg", "a.lbl", "a.lst"))
        value = prg[3]  # $C000: LDA #value
        assert f"start{value}".encode() in labels and f"#${value:02X}".encode() in listing, (prg, labels, listing)
        assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_a_long_command_stops_within_2_s_of_ctrl_c(tmp_path):
    """`retro chart` with two workers, interrupted mid-run: one line, 130, no worker left. (The
    measured latency is in docs/files.md; here 2 s is the bound of the issue, not a benchmark.)"""
    child = subprocess.Popen([sys.executable, "-m", "retro", "chart", "--reduced", "--jobs", "2", "--out",
                              str(tmp_path / "chart")], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             env={**os.environ, "PYTHONPATH": str(ROOT)})
    try:
        line = child.stderr.readline()  # the first progress line: the pool is at work
        assert "accuracy" in line or "cost" in line, line
        workers = _children(child.pid)
        start = time.monotonic()
        child.send_signal(signal.SIGINT)
        err = child.stderr.read()
        child.wait(timeout=30)
        stopped = time.monotonic() - start
    finally:
        child.kill()
    assert child.returncode == 130 and err.strip().endswith("interrupted") and "Traceback" not in err, err
    assert stopped < 2, stopped
    time.sleep(0.2)
    assert not [pid for pid in workers if _alive(pid)]
    assert not (tmp_path / "chart").exists()


def _children(pid: int) -> list[int]:
    listed = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True).stdout
    return [int(n) for n in listed.split()]


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().split(") ")[1][0] != "Z"
    except OSError:
        return False
