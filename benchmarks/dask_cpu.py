"""CPU seconds of one check in one process against the same check on a two-worker embedded Dask cluster
(retro/workers.py), side by side, with the cluster's start apart; and the start time of the small runs
that must not pay for Dask (`retro demo`, `retro check mul8`).

    python benchmarks/dask_cpu.py [ROUTINE ...] [--engine batch] [--repeat N] [--skip-small] [--before DIR]
                                  [--sweep K]

Each check runs in a fresh process (imports apart), in one process and on the workers, N times each
(default 3, alternating): the medians are printed (a shared machine's load moves one run by 10-20%).

Default: hit_slot, mul8 and tile with --exhaustive on the batched core. `--sweep K` adds a sweep-sized run:
mul16's sweep with a from its first K values (K x 65,536 calls, benchmarks/mul16_sweep.py) on the compiled
engine (K = 0: none). The CPU of the worker processes and
of the server they are forked from is read from /proc (psutil) at the cluster's start and before it
closes, the parent's (with the scheduler and the nannies, threads of it) from this process; the JSON of
both runs must be identical (else the script fails).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _records(checks) -> str:
    from retro.commands.check import as_json

    records = as_json(checks)
    for record in records:
        record.pop("compile_seconds", None)
    return json.dumps(records, sort_keys=True)


def one_process(name: str, engine: str) -> dict:
    from retro.analysis.check import run

    began = time.process_time()
    checks = run.run_checks([name], exhaustive=True, jobs=1, engine=engine, search_budget=0)
    return {"cpu": time.process_time() - began, "start": 0.0, "records": _records(checks)}


def _children_cpu() -> float:
    """CPU seconds of every process below this one (the forkserver and the workers forked from it)."""
    import psutil

    spent = 0.0
    for child in psutil.Process().children(recursive=True):
        try:
            times = child.cpu_times()
        except psutil.Error:  # gone meanwhile
            continue
        spent += times.user + times.system
    return spent


def two_workers(name: str, engine: str) -> dict:
    """The CPU of this process and of its children (the worker processes and the server they are forked
    from, which imports the tasks' code once for both) over the check, and of that the cluster's start:
    the children's CPU when it is up and the parent's to import Dask and start it."""
    from retro import workers
    from retro.analysis.check import run

    seen: dict[str, float] = {"import": 0.0}
    real, preload = workers._client, getattr(workers, "_preload", lambda module: None)

    def imported(module: str) -> None:  # imports Dask in this process: part of the start
        before = time.process_time()
        preload(module)
        seen["import"] += time.process_time() - before

    @contextmanager
    def measured(w):
        before = time.process_time()
        with real(w) as client:
            seen["start"] = _children_cpu() + time.process_time() - before + seen["import"]
            yield client
            seen["children"] = _children_cpu()

    workers._client, workers._preload = measured, imported
    run.PARALLEL_CALLS = dict.fromkeys(run.PARALLEL_CALLS, 0)  # on the workers even where the rule would not
    began = time.process_time()
    checks = run.run_checks([name], exhaustive=True, jobs=2, engine=engine, search_budget=0)
    return {"cpu": time.process_time() - began + seen["children"], "start": seen["start"], "records": _records(checks)}


def measured(root: Path, how: str, name: str, engine: str) -> dict:
    """One check measured in a fresh process run from `root` (imports done before the clock starts, no
    cache of a previous run)."""
    done = subprocess.run([sys.executable, __file__, "--measure", how, "--engine", engine, name], cwd=root,
                          capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(root)})
    if done.returncode:
        raise SystemExit(f"{how} {name} in {root}: exit {done.returncode}: {done.stderr[-500:]}")
    return json.loads(done.stdout.splitlines()[-1])


START = """
import sys
from retro.entry import main
code = main(sys.argv[1:])
print("dask imported:", any(m.split(".")[0] in ("dask", "distributed") for m in sys.modules), file=sys.stderr)
raise SystemExit(code)
"""


def start_seconds(root: Path, argv: list[str]) -> tuple[float, float, str]:
    """Wall and CPU seconds of a command in a fresh process run from `root`, and whether it imported Dask."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    began = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", START, *argv], cwd=root, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(root)})
    wall = time.perf_counter() - began
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        raise SystemExit(f"retro {' '.join(argv)} in {root}: exit {done.returncode}: {done.stderr[-300:]}")
    said = done.stderr.strip().splitlines()[-1].split(": ")[-1]
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), said


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("routines", nargs="*", default=[str(ROOT / "examples/object_table/hit_slot.toml"), "mul8",
                                                        "tile"])
    parser.add_argument("--engine", default="batch")
    parser.add_argument("--repeat", type=int, default=3, metavar="N", help="runs of each, medians shown")
    parser.add_argument("--skip-small", action="store_true")
    parser.add_argument("--before", metavar="DIR", help="a checkout of earlier code, timed beside this one")
    parser.add_argument("--sweep", type=int, default=0, metavar="K", help="mul16's sweep for a < K on the compiled engine")
    parser.add_argument("--measure", choices=["one", "two"], help=argparse.SUPPRESS)  # (the fresh process's part)
    args = parser.parse_args()
    if args.measure:
        sys.path.insert(0, os.getcwd())
        import retro.analysis.check.run  # noqa: F401  (imports apart from the measure)
        import retro.commands.check  # noqa: F401

        how = one_process if args.measure == "one" else two_workers
        print(json.dumps(how(args.routines[0], args.engine)))
        return 0
    roots = [("before", Path(args.before).resolve())] if args.before else []
    roots.append(("now", ROOT))
    if not args.skip_small:
        with tempfile.TemporaryDirectory() as out:
            for argv in (["demo", "--out", out], ["check", "mul8", "--quiet"]):
                shown = " ".join(argv[:2])
                for label, root in roots:
                    wall, cpu, dask = start_seconds(root, argv)
                    print(f"retro {shown:<12} {label:<7} {wall:6.2f} s wall {cpu:6.2f} CPU-s  Dask imported: {dask}")
    print(f"{'check --exhaustive':<28} {'code':<7} {'1 process':>10} {'2 workers':>10} {'(start)':>9} {'ratio':>7} "
          f"{'beyond start':>13}")
    checks = [(name, args.engine, Path(name).name if name.endswith(".toml") else name) for name in args.routines]
    with tempfile.TemporaryDirectory() as folder:
        if args.sweep:
            from mul16_sweep import sliced_spec  # benchmarks/: the script's own folder

            checks.append((str(sliced_spec(Path(folder), args.sweep)), "compiled", f"mul16 a < {args.sweep}"))
        return _table(checks, roots, args.repeat)


def _table(checks: list[tuple[str, str, str]], roots: list[tuple[str, Path]], repeat: int) -> int:
    """One row per (check, code): the medians of `repeat` runs in one process and on two workers."""
    for name, engine, label in checks:
        for code, root in roots:
            runs: dict[str, list[dict]] = {"one": [], "two": []}
            for _ in range(repeat):
                for how in runs:
                    runs[how].append(measured(root, how, name, engine))
            if any(run["records"] != runs["one"][0]["records"] for run in runs["one"] + runs["two"]):
                print(f"{name}: the two-worker JSON differs from one process's ({code})", file=sys.stderr)
                return 1
            alone = {"cpu": statistics.median(run["cpu"] for run in runs["one"])}
            two = {key: statistics.median(run[key] for run in runs["two"]) for key in ("cpu", "start")}
            beyond = statistics.median(run["cpu"] - run["start"] for run in runs["two"])
            print(f"{label + ' (' + engine + ')':<28} {code:<7} {alone['cpu']:9.2f}s {two['cpu']:9.2f}s "
                  f"{two['start']:8.2f}s {two['cpu'] / alone['cpu']:6.2f}x {beyond / alone['cpu']:12.2f}x", flush=True)
    return 0

if __name__ == "__main__":
    raise SystemExit(main())
