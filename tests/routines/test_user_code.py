"""Users' Python code in a spec (reference, case generators, [memory] generators) cannot take the tool
down or fake a pass: an exit (any status, sys.exit or os._exit), a hang, endless recursion, a huge
allocation or a nonsense answer is one line naming the function and the case, exit 2.

The exits run in a child process: a guard that failed would end pytest itself, or exit 0 there.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from retro.cli import main

FOREIGN = Path(__file__).resolve().parents[1] / "data" / "foreign"
ROOT = Path(__file__).resolve().parents[2]
ARGUMENTS = "ax, ay, aw, ah, bx, by, bw, bh"
GOOD = "    return int(ax < bx + bw and bx < ax + aw and ay < by + bh and by < ay + ah)\n"


def spec(tmp_path: Path, reference: str = GOOD, *, extra_reference: str = "", cases: str = "random = 50",
         memory: str = "", module: str = "") -> Path:
    """boxhit (ACME's build) with a reference body of our choosing; no `where` (the values keep the
    sums from wrapping): every case counts."""
    (tmp_path / "refs.py").write_text(f"import os, sys\nimport numpy as np\n{module}\n"
                                      f"def boxhit({ARGUMENTS}):\n{reference}\n")
    path = tmp_path / "spec.toml"
    path.write_text(f"""
[program]
file = "{FOREIGN / 'acme_boxhit.prg'}"
symbols = "{FOREIGN / 'acme_boxhit.sym'}"
entry = "boxhit"
[inputs]
ax = {{ at = "boxa_x", values = "1..100" }}
ay = {{ at = "boxa_y", values = "1..100" }}
aw = {{ at = "boxa_w", values = "1..100" }}
ah = {{ at = "boxa_h", values = "1..100" }}
bx = {{ at = "boxb_x", values = "1..100" }}
by = {{ at = "boxb_y", values = "1..100" }}
bw = {{ at = "boxb_w", values = "1..100" }}
bh = {{ at = "boxb_h", values = "1..100" }}
[outputs]
hit = "C"
[reference]
function = "refs.py:boxhit"
time_limit = 1
{extra_reference}
[cases]
{cases}
{memory}
[entry]
d = 0
""")
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "retro", *args], capture_output=True, text=True, timeout=120,
                          cwd=ROOT, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})


def one_line(err: str, *needles: str) -> None:
    assert err.count("\n") == 1, err
    for needle in needles:
        assert needle in err, (needle, err)


def test_the_good_reference_passes(tmp_path, capsys):
    # the fixture itself is sound: every failure below comes from the body swapped in
    assert main(["check", str(spec(tmp_path)), "--jobs", "1"]) == 0


@pytest.mark.parametrize("body, message", [
    ("    sys.exit(0)", "called sys.exit(0)"),
    ("    sys.exit(1)", "called sys.exit(1)"),
    ("    sys.exit()", "called sys.exit(None)"),
    ("    os._exit(0)", "called os._exit(0)"),
    ("    os.abort()", "called os.abort()"),
    ("    raise SystemExit('done')", "called sys.exit('done')"),
])
@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_an_exit_in_the_reference_never_passes(tmp_path, body, message, engine):
    result = run_cli("check", str(spec(tmp_path, body)), "--jobs", "1", "--engine", engine)
    assert result.returncode == 2, result
    one_line(result.stderr, "reference.function refs.py:boxhit", message, "called with ax=")


def test_an_exit_in_a_worker_process_never_passes(tmp_path):
    # 30,000 cases over two workers: the reference runs in the pool's processes
    result = run_cli("check", str(spec(tmp_path, "    os._exit(0)", cases="random = 30000")), "--jobs", "2",
                     "--engine", "scalar")
    assert result.returncode == 2, result
    one_line(result.stderr, "refs.py:boxhit called os._exit(0)")


def test_an_exit_in_an_array_reference_never_passes(tmp_path):
    result = run_cli("check", str(spec(tmp_path, "    os._exit(0)", extra_reference="arrays = true",
                                       cases="random = 30000")), "--jobs", "1")
    assert result.returncode == 2, result
    one_line(result.stderr, "refs.py:boxhit called os._exit(0)", "an array of shape (")


def test_an_exit_at_import_time_never_passes(tmp_path):
    result = run_cli("check", str(spec(tmp_path, module="sys.exit(0)")), "--jobs", "1")
    assert result.returncode == 2, result
    one_line(result.stderr, "reference.function: refs.py failed to import: refs.py called sys.exit(0)")


@pytest.mark.parametrize("body, message", [
    ("    while True:\n        pass", "took more than 1 s"),
    ("    import time\n    time.sleep(30)", "took more than 1 s"),
    (f"    return boxhit({ARGUMENTS})", "recursed without end"),
    ("    return len([0] * (1 << 28))", "allocated more than 512 MiB"),
    ("    return np.zeros(1 << 40, dtype=np.uint8).size", "allocated more than 512 MiB"),
])
def test_a_hang_recursion_or_huge_allocation_is_one_line(tmp_path, capsys, body, message):
    assert main(["check", str(spec(tmp_path, body)), "--jobs", "1"]) == 2
    one_line(capsys.readouterr().err, "refs.py:boxhit", message, "called with ax=")


@pytest.mark.parametrize("body, message", [
    ("    return 10 ** 5000", "returned an integer of 16610 bits for hit"),
    ("    return float('nan')", "returned nan for hit"),
    ("    return [0] * 5", "returned [0, 0, 0, 0, 0] for hit"),
    ("    return 'yes'", "returned 'yes' for hit"),
])
def test_a_nonsense_answer_is_one_line(tmp_path, capsys, body, message):
    assert main(["check", str(spec(tmp_path, body)), "--jobs", "1"]) == 2
    one_line(capsys.readouterr().err, "refs.py:boxhit", message, "(inputs ax=")


@pytest.mark.parametrize("body, message", [
    ("    return {'hit': np.full(len(ax), 10 ** 5000, dtype=object)}", "returned object of shape"),
    ("    return np.full(len(ax), np.nan)", "returned float64 of shape"),
    ("    return np.zeros(3, dtype=np.int64)", "of shape (3,)"),
])
def test_a_nonsense_array_answer_is_one_line(tmp_path, capsys, body, message):
    path = spec(tmp_path, body, extra_reference="arrays = true", cases="random = 30000")
    assert main(["check", str(path), "--jobs", "1"]) == 2
    one_line(capsys.readouterr().err, "refs.py:boxhit", message)


@pytest.mark.parametrize("key, body, message", [
    ("boundary", "    sys.exit(0)", "cases.boundary refs.py:gen called sys.exit(0)"),
    ("boundary", "    os._exit(0)", "cases.boundary refs.py:gen called os._exit(0)"),
    ("boundary", "    return [(1, 2, 3, 4, 5, 6, 7, 10 ** 5000)]", "bh must be a whole number"),
    ("boundary", "    return [(1, 2, 3, 4, 5, 6, 7, float('nan'))]", "bh must be a whole number"),
    ("boundary", "    raise ValueError('no')", "cases.boundary refs.py:gen raised ValueError: no"),
    ("sweep", "    yield (1, 2, 3, 4, 5, 6, 7, 8)\n    while True:\n        pass",
     "cases.sweep refs.py:gen (item 2) took more than 1 s"),
    ("sweep", "    yield from gen()", "cases.sweep refs.py:gen (item 1) recursed without end"),
    ("random_generator", "    return [(1, 2, 3, 4, 5, 6, 7, 8)] * 3", "asked for 50 cases, the function returned 3"),
    ("random_generator", "    return 5", "the function must return a list or iterable of cases"),
    ("boundary", "    return [len([0] * (1 << 28))]", "cases.boundary refs.py:gen allocated more than 512 MiB"),
    ("boundary", "    while True:\n        pass", "cases.boundary refs.py:gen took more than 1 s"),
])
def test_a_case_generator_that_fails_is_one_line(tmp_path, key, body, message):
    path = spec(tmp_path, cases=f'random = 50\n{key} = "refs.py:gen"',
                module=f"def gen(rng=None, n=None):\n{body}\n")
    result = run_cli("check", str(path), "--jobs", "1", "--exhaustive", "--random", "50")
    assert result.returncode == 2, result
    one_line(result.stderr, message)


@pytest.mark.parametrize("body, message", [
    ("    return np.zeros(1 << 28, dtype=np.uint8)", "returned 268,435,456 bytes: expected 1 to"),
    ("    return [1.5, 2]", "returned 1.5 at index 0: bytes are whole numbers 0..255"),
    ("    return np.array([1.5, 2])", "returned an array of shape (2,) (float64)"),
    ("    return [10 ** 5000]", "returned an integer of 16610 bits at index 0"),
    ("    return [256]", "returned 256 at index 0"),
    ("    return []", "returned 0 bytes"),
    ("    os._exit(0)", "memory.table.generator refs.py:table called os._exit(0)"),
])
def test_a_memory_generator_is_checked_by_size_and_kind(tmp_path, body, message):
    path = spec(tmp_path, memory='[memory]\ntable = { at = "$2000", generator = "refs.py:table" }',
                module=f"def table(rng=None):\n{body}\n")
    result = run_cli("check", str(path), "--jobs", "1")
    assert result.returncode == 2, result
    one_line(result.stderr, "memory.table", message)


@pytest.mark.parametrize("value", ["0", "3601", "1.5", "true", '"ten"'])
def test_the_time_limit_is_checked(tmp_path, capsys, value):
    path = spec(tmp_path)
    path.write_text(path.read_text().replace("time_limit = 1", f"time_limit = {value}"))
    assert main(["check", str(path), "--jobs", "1"]) == 2
    one_line(capsys.readouterr().err, "reference.time_limit")


def test_the_time_limit_can_be_raised(tmp_path, capsys):
    # a reference that takes 1.5 s once: over a limit of 1 s, within one of 3 s
    slow = "    global SLEPT\n    if not SLEPT:\n        SLEPT = True\n        time.sleep(1.5)\n" + GOOD
    path = spec(tmp_path, slow, module="import time\nSLEPT = False")
    assert main(["check", str(path), "--jobs", "1", "--random", "5"]) == 2
    assert "took more than 1 s" in capsys.readouterr().err
    path.write_text(path.read_text().replace("time_limit = 1", "time_limit = 3"))
    (tmp_path / "refs.py").write_text((tmp_path / "refs.py").read_text() + "\n")  # a new module, SLEPT again False
    assert main(["check", str(path), "--jobs", "1", "--random", "5"]) == 0, capsys.readouterr().err


def peak_of(*args: str) -> tuple[int, int]:
    """(exit status, peak resident KiB) of `retro ARGS`, run as the only child of a fresh interpreter
    (RUSAGE_CHILDREN then holds that command's peak alone)."""
    script = ("import resource, subprocess, sys\n"
              "code = subprocess.run([sys.executable, '-m', 'retro', *sys.argv[1:]], capture_output=True).returncode\n"
              "print(code, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n")
    result = subprocess.run([sys.executable, "-c", script, *args], capture_output=True, text=True, timeout=120,
                            cwd=ROOT, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    code, peak = result.stdout.split()
    return int(code), int(peak)


def test_a_256_mb_memory_generator_is_refused_before_it_costs_gigabytes(tmp_path):
    # converted to Python ints first, 256 MB of bytes cost 2.2 GB; refused by size, the array itself
    path = spec(tmp_path, memory='[memory]\ntable = { at = "$2000", generator = "refs.py:table" }',
                module="def table(rng=None):\n    return np.ones(1 << 28, dtype=np.uint8)\n")
    code, peak = peak_of("check", str(path), "--jobs", "1")
    assert code == 2 and peak < 600 * 1024, peak


def test_a_where_that_would_build_gigabytes_costs_nothing(tmp_path):
    path = spec(tmp_path)
    path.write_text(path.read_text().replace("[cases]", '[cases]\nwhere = "len([0] * (1 << 28)) > 0"'))
    code, peak = peak_of("check", str(path), "--jobs", "1")
    assert code == 2 and peak < 300 * 1024, peak


def test_the_time_limit_leaves_an_outer_timer_its_time():
    """A caller's own SIGALRM timer (a test harness's, say) still fires at its time inside a guarded call,
    and keeps its remaining time after one."""
    import signal
    import time

    from retro.routines.sandbox import UserCodeError, guarded

    class Outer(Exception):
        pass

    def outer(signum, frame):
        raise Outer()

    previous = signal.signal(signal.SIGALRM, outer)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.5)
        start = time.monotonic()
        with pytest.raises(Outer):
            guarded(lambda: time.sleep(5), "t:sleep", 3)()
        assert time.monotonic() - start < 2
        signal.alarm(10)
        with pytest.raises(UserCodeError, match="t:sleep took more than 0.5 s"):
            guarded(lambda: time.sleep(5), "t:sleep", 0.5)()
        assert 8 <= signal.alarm(0) <= 10
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def test_an_exit_when_a_module_by_name_is_imported_never_passes(tmp_path):
    (tmp_path / "exitmod.py").write_text("import sys\nsys.exit(0)\n")
    path = spec(tmp_path)
    path.write_text(path.read_text().replace("refs.py:boxhit", "exitmod:boxhit"))
    result = subprocess.run([sys.executable, "-m", "retro", "check", str(path), "--jobs", "1"], capture_output=True,
                            text=True, timeout=120, cwd=ROOT,
                            env={"PYTHONPATH": f"{ROOT}:{tmp_path}", "PATH": "/usr/bin:/bin"})
    assert result.returncode == 2, result
    one_line(result.stderr, "reference.function: exitmod failed to import: exitmod called sys.exit(0)")
