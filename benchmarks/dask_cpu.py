"""CPU seconds of one check in one process against the same check on a two-worker embedded Dask cluster
(retro/workers.py), side by side, with the cluster's start apart; and the start time of the small runs
that must not pay for Dask (`retro demo`, `retro check mul8`).

    python benchmarks/dask_cpu.py [ROUTINE ...] [--engine batch] [--skip-small] [--before DIR]

Default: mul8 and aabb8 with --exhaustive on the batched core. The workers' CPU is read from the workers
themselves (time.process_time in each, at the cluster's start and before it closes), the parent's from
this process; the JSON of both runs must be identical (else the script fails).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from retro import workers  # noqa: E402
from retro.analysis.check import run  # noqa: E402
from retro.commands.check import as_json  # noqa: E402


def _records(checks) -> str:
    records = as_json(checks)
    for record in records:
        record.pop("compile_seconds", None)
    return json.dumps(records, sort_keys=True)


def one_process(name: str, engine: str) -> tuple[float, str]:
    began = time.process_time()
    checks = run.run_checks([name], exhaustive=True, jobs=1, engine=engine, search_budget=0)
    return time.process_time() - began, _records(checks)


def two_workers(name: str, engine: str) -> tuple[float, float, float, float, str]:
    """(parent CPU, workers' CPU, of which their start, the parent's CPU to start the cluster, JSON)."""
    seen: dict[str, dict] = {}
    real = workers._client

    @contextmanager
    def measured(w):
        before = time.process_time()
        with real(w) as client:
            seen["start"] = client.run(time.process_time)
            seen["parent_start"] = {"": time.process_time() - before}
            yield client
            seen["end"] = client.run(time.process_time)

    workers._client = measured
    rule = run.PARALLEL_CALLS
    run.PARALLEL_CALLS = dict.fromkeys(rule, 0)  # on the workers even where the rule would keep it in one process
    try:
        began = time.process_time()
        checks = run.run_checks([name], exhaustive=True, jobs=2, engine=engine, search_budget=0)
        parent = time.process_time() - began
    finally:
        workers._client, run.PARALLEL_CALLS = real, rule
    return (parent, sum(seen["end"].values()), sum(seen["start"].values()), seen["parent_start"][""],
            _records(checks))


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
    parser.add_argument("routines", nargs="*", default=["mul8", "aabb8"])
    parser.add_argument("--engine", default="batch")
    parser.add_argument("--skip-small", action="store_true")
    parser.add_argument("--before", metavar="DIR", help="a checkout of the code before Dask, timed beside this one")
    args = parser.parse_args()
    if not args.skip_small:
        import tempfile

        with tempfile.TemporaryDirectory() as out:
            for argv in (["demo", "--out", out], ["check", "mul8", "--quiet"]):
                shown = " ".join(argv[:2])
                for label, root in (("before", args.before), ("now", ROOT)):
                    if root is None:
                        continue
                    wall, cpu, dask = start_seconds(Path(root), argv)
                    print(f"retro {shown:<12} {label:<7} {wall:6.2f} s wall {cpu:6.2f} CPU-s  Dask imported: {dask}")
    print(f"{'check --exhaustive':<22} {'1 process':>10} {'2 workers':>10} {'(start)':>9} {'ratio':>7} "
          f"{'beyond start':>13}")
    for name in args.routines:
        alone, expected = one_process(name, args.engine)
        parent, spent, start, parent_start, got = two_workers(name, args.engine)
        if got != expected:
            print(f"{name}: the two-worker JSON differs from one process's", file=sys.stderr)
            return 1
        total = parent + spent
        beyond = total - start - parent_start
        print(f"{name + ' (' + args.engine + ')':<22} {alone:9.2f}s {total:9.2f}s {start + parent_start:8.2f}s "
              f"{total / alone:6.2f}x {beyond / alone:12.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
