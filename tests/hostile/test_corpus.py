"""The generated hostile corpus (corpus.py) through every command: each case ends with exit status 0,
1 or 2, at most one line on stderr (argparse's own usage + error pair for a malformed command line),
never a traceback, within a time bound, and leaves no output file behind when it fails. An error
names what is at fault: the file and the key of a TOML value, the option (or the file an option
names); an empty file name is refused, never taken for the option's absence. CI runs a
seeded sample per command; RETRO_EXHAUSTIVE=1 runs every case."""

from __future__ import annotations

import contextlib
import io
import os
import random
import signal
from pathlib import Path

import pytest
from corpus import cases

from retro.cli import main

FULL = os.environ.get("RETRO_EXHAUSTIVE") == "1"
PER_COMMAND = {"vic": 80, "nes": 80, "check": 40, "advise": 6, "run": 40, "asm": 20, "cycles": 15, "parry": 8}
SECONDS_PER_CASE = 120


class Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise Timeout()


def sample() -> list:
    by_command: dict[str, list] = {}
    for case in cases():
        by_command.setdefault(case.argv[0], []).append(case)
    if FULL:
        return [c for group in by_command.values() for c in group]
    rng = random.Random(0x6502)
    return [c for command, group in by_command.items()
            for c in rng.sample(group, min(len(group), PER_COMMAND.get(command, 10)))]


def run_case(case, folder: Path) -> str | None:
    """None when the case behaved, else what went wrong."""
    folder.mkdir()
    for name, content in case.files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content if isinstance(content, bytes) else content.encode())
    before = {p for p in folder.rglob("*")}
    argv = [a.replace("{dir}", str(folder)) for a in case.argv]
    out, err = io.StringIO(), io.StringIO()
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(SECONDS_PER_CASE)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exit_:  # argparse
                code = exit_.code
    except Timeout:
        return f"no answer in {SECONDS_PER_CASE} s"
    except BaseException as exc:  # what escaped main(): a traceback for the user
        return f"raised {type(exc).__name__}: {str(exc)[:120]}"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    text = err.getvalue()
    lines = text.splitlines()
    if code not in (0, 1, 2):
        return f"exit status {code!r}"
    if "Traceback" in text:
        return "a traceback on stderr"
    argparse_pair = len(lines) == 2 and lines[0].startswith("usage:")
    progress = [line for line in lines if line.startswith(("check ", "cost:", "evaluate", "advise"))]
    if len(lines) - len(progress) > 1 and not argparse_pair:
        return f"{len(lines)} lines on stderr: {lines[:3]}"
    if code == 2 and not lines:
        return "exit 2 without a message"
    if case.refused and code != 2:
        return f"accepted (exit {code}): an empty file name"
    message = "\n".join(line for line in lines if not line.startswith(("check ", "cost:", "evaluate", "advise")))
    if code == 2 and not argparse_pair:
        missing = [name for name in case.names if name not in message]
        if missing:
            return f"the error does not name {missing[0]!r}: {message[:160]}"
    if code != 0:
        left = {p for p in folder.rglob("*")} - before
        written = [p for p in left if p.is_file()]
        if written:
            return f"failed but wrote {written[0].name}"
    return None


@pytest.mark.exhaustive
def test_the_hostile_corpus(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # outputs named by a bare hostile value land here, not in the checkout
    failures = []
    chosen = sample()
    for i, case in enumerate(chosen):
        problem = run_case(case, tmp_path / f"case{i}")
        if problem:
            failures.append(f"{case.name}: {problem}")
    assert len(chosen) >= 200
    assert not failures, f"{len(failures)} of {len(chosen)} cases misbehaved, e.g. " + "; ".join(failures[:8])


def _report() -> None:
    """Every case; the numbers for docs/hostile.md (`python tests/hostile/test_corpus.py`)."""
    import resource
    import sys
    import tempfile
    import time

    all_cases = list(cases())
    started, failures = time.time(), 0
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        for i, case in enumerate(all_cases):
            problem = run_case(case, Path(tmp) / f"case{i}")
            if problem:
                failures += 1
                print(f"{case.name}: {problem}", flush=True)
        elapsed = time.time() - started  # before the folder of 18,000 cases is removed
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss >> 10
    print(f"{len(all_cases)} cases, {len(all_cases) - failures} clean, {elapsed:.0f} s, peak {peak} MiB",
          file=sys.stderr)


if __name__ == "__main__":
    _report()
