"""The mutational fuzzer (fuzz.py) through the commands that read each format. Clean means: success,
or exit 2 with one line on stderr that names the mutated file (and the key, for a value of the wrong
type), or exit 1 where the file is a program or spec whose routine may fail (one line, or a failed
check's report on stdout); never a
traceback, never more than SECONDS_PER_CASE, and (in the subprocess sample) peak memory under
1 GiB. CI runs a deterministic sample (a few cases of every format, seconds); RETRO_EXHAUSTIVE=1
runs every case of both seeds. Each case runs in-process through `retro.cli.main` (the command
functions, as the CLI calls them); a method file, whose only command (`advise`) takes seconds,
through its loader. A small sample also runs as `python -m retro` to check the real exit status,
stderr and memory. `python tests/hostile/test_fuzz.py` runs them all and prints the numbers that
docs/hostile.md records."""

from __future__ import annotations

import contextlib
import io
import os
import random
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from fuzz import ROOT, Case, cases, seeds

from retro.cli import main
from retro.errors import InputError

FULL = os.environ.get("RETRO_EXHAUSTIVE") == "1"
PER_FORMAT = 4  # cases per format in the CI sample
SLOW_FORMATS = {"routine spec": 2, "Ophis source": 2}  # seconds a case: fewer of them in the sample
SECONDS_PER_CASE = 60
SUBPROCESS_SAMPLE = 6
MEMORY_LIMIT = 1 << 30


class Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise Timeout()


def sample(all_cases: list[Case]) -> list[Case]:
    if FULL:
        return all_cases
    by_format: dict[str, list[Case]] = {}
    for case in all_cases:
        by_format.setdefault(case.seed.format, []).append(case)
    rng = random.Random(0xC64)
    return [case for name, group in by_format.items()
            for case in rng.sample(group, min(len(group), SLOW_FORMATS.get(name, PER_FORMAT)))]


def write_case(case: Case, folder: Path) -> list[str]:
    """The case's files in a fresh folder; its command line."""
    folder.mkdir(parents=True)
    for name, content in {**case.seed.target.files, case.seed.name: case.data}.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(content if isinstance(content, bytes) else content.encode())
    return [a.replace("{dir}", str(folder)).replace("{file}", case.seed.name) for a in case.seed.target.argv]


def _call(case: Case, folder: Path, argv: list[str]) -> tuple[int, str]:
    """(exit status, stderr) of the command, in-process."""
    err = io.StringIO()
    if case.seed.target.command == "method":
        from retro.analysis.study.methods.user import load_method_file

        try:
            load_method_file(str(folder / case.seed.name))
        except InputError as exc:
            return 2, f"retro advise: {exc}\n"
        return 0, ""
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exit_:  # argparse
            code = exit_.code
    return code, err.getvalue()


def judge(case: Case, code, stderr: str) -> str | None:
    """None when the outcome is clean, else what is wrong with it."""
    lines = [line for line in stderr.splitlines() if line.strip()]
    if code not in (0, 1, 2):
        return f"exit status {code!r}"
    if "Traceback" in stderr:
        return "a traceback on stderr"
    if code == 0:
        return None
    if code == 1 and not case.seed.target.exit_1_allowed:
        return f"exit 1 for a bad input: {lines[:1]}"
    if code == 1:  # the routine failed: a line on where it stopped, or a failed check's report on stdout
        return None if len(lines) <= 1 else f"{len(lines)} lines on stderr: {lines[:3]}"
    if len(lines) != 1:
        return f"{len(lines)} lines on stderr: {lines[:3]}"
    if Path(case.seed.name).name not in lines[0]:
        return f"the error does not name {case.seed.name}: {lines[0][:200]}"
    if case.field and case.field not in lines[0]:
        return f"the error does not name the key {case.field!r}: {lines[0][:200]}"
    return None


def run_case(case: Case, folder: Path) -> str | None:
    argv = write_case(case, folder)
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(SECONDS_PER_CASE)
    try:
        code, stderr = _call(case, folder, argv)
    except Timeout:
        return f"no answer in {SECONDS_PER_CASE} s"
    except BaseException as exc:  # what escaped: a traceback for the user
        return f"raised {type(exc).__name__}: {str(exc)[:160]}"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    return judge(case, code, stderr)


def run_subprocess(case: Case, folder: Path) -> str | None:
    """The case as a user runs it: real exit status, stderr, and the process's peak memory."""
    argv = write_case(case, folder)
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    done = subprocess.run([sys.executable, "-m", "retro", *argv], capture_output=True, text=True,
                          timeout=SECONDS_PER_CASE, cwd=folder, env={**os.environ, "PYTHONPATH": str(ROOT)})
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024  # KiB on Linux
    if peak > MEMORY_LIMIT and peak > before * 1024:
        return f"peak memory {peak >> 20} MiB"
    return judge(case, done.returncode, done.stderr)


def test_every_seed_is_read_as_it_is(tmp_path, monkeypatch):
    """The seeds are valid files, read to the end: a mutation's error is the mutation's doing."""
    monkeypatch.chdir(tmp_path)
    outcomes = {}
    for i, seed in enumerate(seeds()):
        case = Case(seed, "as it is", seed.data)
        argv = write_case(case, tmp_path / f"seed{i}")
        outcomes[seed.format] = _call(case, tmp_path / f"seed{i}", argv)
    assert {name: outcome for name, outcome in outcomes.items() if outcome[0] != 0} == {}


@pytest.mark.exhaustive
def test_every_mutated_file_gives_a_result_or_one_line_naming_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    chosen = sample(list(cases()))
    failures = [f"{case.name}: {problem}" for i, case in enumerate(chosen)
                if (problem := run_case(case, tmp_path / f"case{i}"))]
    assert len({case.seed.format for case in chosen}) >= 20
    assert not failures, f"{len(failures)} of {len(chosen)} cases misbehaved, e.g. " + "; ".join(failures[:6])


def test_a_sample_as_the_user_runs_it(tmp_path):
    runnable = [case for case in cases() if case.seed.target.argv and case.seed.target.command != "spec"]
    chosen = random.Random(0x1541).sample(runnable, SUBPROCESS_SAMPLE)
    failures = [f"{case.name}: {problem}" for i, case in enumerate(chosen)
                if (problem := run_subprocess(case, tmp_path / f"case{i}"))]
    assert not failures, "; ".join(failures)


def _report() -> None:
    """Every case in-process; the numbers for docs/hostile.md."""
    import tempfile

    all_cases = list(cases())
    started = time.time()
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        os.chdir(tmp)
        for i, case in enumerate(all_cases):
            problem = run_case(case, Path(tmp) / f"case{i}")
            if problem:
                failures.append(f"{case.name}: {problem}")
                print(failures[-1], flush=True)
        elapsed = time.time() - started  # before the case folders are removed
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss >> 10
    print(f"{len(all_cases)} cases, {len(all_cases) - len(failures)} clean, {elapsed:.0f} s, "
          f"peak {peak} MiB")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    _report()
