"""The long commands' parallel work on Dask (retro/workers.py): results in task order whatever order the
tasks finish in, workers that leave Ctrl-C to their parent and die with it, no worker left after
Ctrl-C, the same check JSON on a two-worker cluster as in one process, and small runs that never
import Dask."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from retro import workers
from retro.workers import Workers, run_in_order

ROOT = Path(__file__).resolve().parent.parent
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
ENV.pop(workers.SCHEDULER_ENV, None)

PARENT = """
import os, time
from retro.workers import Workers, run_in_order

def report(pid):
    print(pid, flush=True)
    time.sleep(60)

run_in_order(os.getpid, [()], Workers(2), report)
"""


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie waiting for its (dead) parent's reaper counts as gone
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().split(") ")[1][0] != "Z"
    except OSError:
        return False


def _descendants(pid: int) -> list[int]:
    """Every process below `pid` (the embedded cluster's workers are the forkserver's children)."""
    listed = subprocess.run(["ps", "-e", "-o", "pid=,ppid="], capture_output=True, text=True).stdout
    children: dict[int, list[int]] = {}
    for line in listed.splitlines():
        child, parent = (int(n) for n in line.split())
        children.setdefault(parent, []).append(child)
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def _gone(pids: list[int], seconds: float = 10) -> list[int]:
    deadline = time.monotonic() + seconds
    while any(_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    return [p for p in pids if _alive(p)]


def _slow_square(n: int, seconds: float) -> int:
    time.sleep(seconds)
    return n * n


def test_results_come_in_task_order_whatever_order_tasks_finish_in():
    got = []
    tasks = [(n, 0.6 if n % 2 == 0 else 0.0) for n in range(6)]  # the even ones finish after the next odd one
    run_in_order(_slow_square, tasks, Workers(2), got.append)
    assert got == [n * n for n in range(6)]


def test_a_report_returning_true_ends_the_run():
    got = []
    run_in_order(_slow_square, [(n, 0.0) for n in range(50)], Workers(2), lambda r: got.append(r) or len(got) == 3)
    assert got == [0, 1, 4]


def test_one_worker_runs_in_this_process():
    assert run_in_order(os.getpid, [()], Workers(1), lambda pid: pid == os.getpid()) is None


def test_workers_ignore_ctrl_c():
    handlers = []
    run_in_order(signal.getsignal, [(signal.SIGINT,)] * 2, Workers(2), handlers.append)
    assert handlers == [signal.SIG_IGN, signal.SIG_IGN]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and ps")
def test_a_killed_parent_takes_its_workers_with_it():
    parent = subprocess.Popen([sys.executable, "-c", PARENT], stdout=subprocess.PIPE, text=True, env=ENV)
    try:
        worker = int(parent.stdout.readline())
        below = _descendants(parent.pid)
        assert worker in below and _alive(worker)
    finally:
        parent.send_signal(signal.SIGKILL)
        parent.wait()
    assert not _gone(below), "a worker outlived its killed parent"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and ps")
def test_ctrl_c_cancels_the_sweep_and_leaves_no_worker():
    """Ctrl-C in a terminal reaches the whole process group: the command ends with its one line and
    130, and no process it started is left."""
    child = subprocess.Popen([sys.executable, "-m", "retro", "check", "aabb8", "--exhaustive", "--engine", "batch",
                              "--jobs", "2", "--no-search"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True, env=ENV, start_new_session=True)
    try:
        line = child.stderr.readline()  # the first progress line: the sweep is on the workers
        assert "check aabb8" in line, line
        below = _descendants(child.pid)
        assert len(below) >= 2, below
        os.killpg(child.pid, signal.SIGINT)
        err = child.stderr.read()
        child.wait(timeout=30)
    finally:
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGKILL)
    assert child.returncode == 130 and err.strip().endswith("interrupted") and "Traceback" not in err, err
    assert "leaked" not in err, err  # the cluster's semaphores released (multiprocessing's resource tracker)
    assert not _gone(below), "a worker outlived the interrupted command"


def _records(checks) -> list[dict]:
    from retro.commands.check import as_json

    records = as_json(checks)
    for record in records:
        record.pop("compile_seconds", None)  # a timing
    return records


ROUTINES = ["mul8", "tile", str(ROOT / "examples" / "boxhit" / "boxhit.toml")]


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_a_two_worker_cluster_gives_the_same_json_as_one_process(monkeypatch, engine):
    from retro.analysis.check import run

    one = _records(run.run_checks(ROUTINES, jobs=1, engine=engine, search_budget=0))
    monkeypatch.setattr(run, "PARALLEL_CALLS", dict.fromkeys(run.PARALLEL_CALLS, 0))  # every check on the workers
    used = []
    real = workers._client

    def counted(w):
        used.append(w)
        return real(w)
    monkeypatch.setattr(workers, "_client", counted)
    two = _records(run.run_checks(ROUTINES, jobs=2, engine=engine, search_budget=0))
    assert used == [Workers(2)]  # one cluster for the three routines
    assert json.dumps(two, sort_keys=True) == json.dumps(one, sort_keys=True)


@pytest.mark.parametrize("spec", [str(ROOT / "tests/data/sweeps/mul8_yielded.toml"), "mul8"])
def test_a_sweep_in_many_tasks_gives_the_same_json(monkeypatch, spec):
    """A sweep function that yields its cases does not say how many: tasks go out until one comes back
    short, and the workers make the cases themselves (dropping those of the other worker's tasks). A
    grid sweep (mul8's) is counted and each worker enters it at its range."""
    from retro.analysis.check import run

    one = _records(run.run_checks([spec], exhaustive=True, jobs=1, engine="batch", search_budget=0))
    monkeypatch.setattr(run, "PARALLEL_CALLS", dict.fromkeys(run.PARALLEL_CALLS, 0))
    monkeypatch.setattr(run, "TASK_BLOCKS", 1)  # 3 tasks and more
    used = []
    real = workers._client
    monkeypatch.setattr(workers, "_client", lambda w: used.append(w) or real(w))
    two = _records(run.run_checks([spec], exhaustive=True, jobs=2, engine="batch", search_budget=0))
    assert one[0]["cases"] > 2 * 65_536 and used == [Workers(2)]
    assert json.dumps(two, sort_keys=True) == json.dumps(one, sort_keys=True)


def test_a_sweep_runs_on_an_existing_cluster_given_by_its_address(monkeypatch):
    from distributed import LocalCluster

    from retro.analysis.check import run
    from retro.commands.check import check

    one = _records(check(["mul8"], jobs=1, search=0))
    monkeypatch.setattr(run, "PARALLEL_CALLS", dict.fromkeys(run.PARALLEL_CALLS, 0))
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=True, dashboard_address=":0") as cluster:
        monkeypatch.setenv(workers.SCHEDULER_ENV, cluster.scheduler_address)
        from_env = _records(check(["mul8"], search=0))
        monkeypatch.delenv(workers.SCHEDULER_ENV)
        given = _records(check(["mul8"], search=0, scheduler=cluster.scheduler_address))
    assert from_env == one and given == one


def test_a_scheduler_that_does_not_answer_is_one_line(monkeypatch):
    from retro.analysis.check import run
    from retro.commands.check import check
    from retro.errors import InputError

    monkeypatch.setattr(run, "PARALLEL_CALLS", dict.fromkeys(run.PARALLEL_CALLS, 0))
    monkeypatch.setattr(workers, "CONNECT_SECONDS", 1)
    with pytest.raises(InputError, match=r"--scheduler tcp://127.0.0.1:9: no Dask scheduler answers there"):
        check(["mul8"], search=0, scheduler="tcp://127.0.0.1:9")


COMPILED_ON_WORKERS = """
import json, sys
import multiprocessing.forkserver as forkserver
from retro.analysis.check import run
from retro.commands.check import as_json

asked = []
real = forkserver.set_forkserver_preload
forkserver.set_forkserver_preload = lambda names: asked.extend(names) or real(names)

def records(checks):
    return json.dumps([{k: v for k, v in r.items() if k != "compile_seconds"} for r in as_json(checks)], sort_keys=True)

run.PARALLEL_CALLS = dict.fromkeys(run.PARALLEL_CALLS, 0)  # (the agreement loads the compiled code here first)
two = records(run.run_checks(["mul8"], exhaustive=True, jobs=2, engine="compiled", search_budget=0))
one = records(run.run_checks(["mul8"], exhaustive=True, jobs=1, engine="compiled", search_budget=0))
print(json.dumps({"same": one == two, "engine": json.loads(two)[0]["engine"], "preloaded": asked}))
"""


def test_compiled_workers_fork_from_a_server_with_numba_ready_and_give_the_same_json():
    """With the compiled engine in use, the server the workers are forked from imports numba and makes its
    CPU target ready (retro/cpu/numba_ready.py) once for all of them; a sweep on two such workers gives
    the JSON of one process."""
    from retro.cpu.compiled import numba_problem

    if numba_problem() is not None:
        pytest.skip(numba_problem())
    done = subprocess.run([sys.executable, "-c", COMPILED_ON_WORKERS], capture_output=True, text=True, env=ENV,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    said = json.loads(done.stdout.splitlines()[-1])
    assert said["same"] and said["engine"] == "compiled"
    assert {"numba", "retro.cpu.numba_ready", "retro.analysis.check.run"} <= set(said["preloaded"])


def test_the_server_makes_numba_ready_only_after_this_process_loaded_compiled_code(monkeypatch):
    """Any check imports numba (to ask whether it can be used); only a process that loaded compiled code
    (numba's array implementations imported) has its workers' server import numba and make it ready."""
    monkeypatch.delitem(sys.modules, "numba.np.arraymath", raising=False)
    assert workers.server_preload("tasks") == ["distributed", "tasks"]
    monkeypatch.setitem(sys.modules, "numba.np.arraymath", sys)
    assert workers.server_preload("tasks") == ["distributed", "tasks", "numba", "retro.cpu.numba_ready"]


def test_numba_ready_installs_the_target_a_first_compiled_load_would():
    """Imported, it loads numba's implementation registries (what a worker's first compiled load did)."""
    from retro.cpu.compiled import numba_problem

    if numba_problem() is not None:
        pytest.skip(numba_problem())
    probe = ("import sys, numba\nbefore = 'numba.np.arraymath' in sys.modules\nfrom retro.cpu import numba_ready\n"
             "print(before, numba_ready.READY, 'numba.np.arraymath' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=ENV, timeout=120)
    assert done.stdout.split() == ["False", "True", "True"], done.stderr[-2000:]


SMALL = """
import sys
from retro.entry import main
code = main(["check", "mul8", "--quiet", "--jobs", "2"])
heavy = sorted(m for m in sys.modules if m.split(".")[0] in ("dask", "distributed"))
print(code, heavy, file=sys.stderr)
"""


def test_a_small_check_never_imports_dask():
    """`retro check mul8` (two workers allowed) runs in its own process: Dask is never imported."""
    done = subprocess.run([sys.executable, "-c", SMALL], capture_output=True, text=True, env=ENV, timeout=300)
    assert done.stderr.strip().splitlines()[-1] == "0 []", done.stderr


def _late_even_tasks(sweep, first, count):
    """sweep_task with every even task finishing after the next odd one (in a worker process)."""
    from retro.analysis.check import run

    if (first // count) % 2 == 0:
        time.sleep(0.5)
    return run.sweep_task(sweep, first, count)


def test_chunks_finishing_out_of_order_give_the_same_json_and_progress_as_they_merge(monkeypatch):
    """The tasks' tallies are merged in task order whatever order they finish in; a progress line
    comes as each is merged, counting the cases merged so far."""
    from retro.analysis.check import run

    spec = str(ROOT / "examples" / "object_table" / "hit_slot.toml")
    one = _records(run.run_checks([spec], jobs=1, engine="scalar", search_budget=0, random_count=30_000))
    monkeypatch.setattr(run, "PARALLEL_CALLS", dict.fromkeys(run.PARALLEL_CALLS, 0))
    monkeypatch.setattr(run, "TASK_BLOCKS", 1)  # 4,096 sampled + 30,000 random cases: tasks of 4,000 cases
    monkeypatch.setattr(run, "PROGRESS_SECONDS", 0.0)
    monkeypatch.setattr(run, "sweep_task", _late_even_tasks)  # (the workers' own run module keeps the real one)
    lines = []
    two = _records(run.run_checks([spec], jobs=2, engine="scalar", search_budget=0, random_count=30_000,
                                  progress=lines.append))
    assert json.dumps(two, sort_keys=True) == json.dumps(one, sort_keys=True)
    done = [int(line.split(": ")[1].split("/")[0].replace(",", "")) for line in lines if "/" in line]
    assert len(done) >= 8 and done == sorted(done) and done[-1] == 4_096 + 30_000, lines
