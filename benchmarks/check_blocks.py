"""What a check of many blocks costs beyond its engine's calls, and what `retro check` costs to start: this
tree against another revision, side by side in one run (CPU seconds: time.process_time in a process, getrusage
of the children for whole processes; the machine is shared, so each figure is the best of ROUNDS, the two trees
run alternately, and the load is printed with each line).

Per routine (default: the built-ins whose --exhaustive sweep is many 65,536-case blocks): a warm check in one
process (imports, numba and the compiled code loaded: a first check_routine(spec, exhaustive=True,
search_budget=0) run and dropped, then the best of ROUNDS), and the sweep's blocks apart: making them
(retro.routines.cases.stream), their engine calls (run_on_batched_core) and their tally (count_array_block: the
reference, the domain, the counts), in ms a block. Then start-up: `retro check --help` and `retro check mul8`
in fresh processes; with --set, the issue's set in ONE process (`retro check aabb_edges ... tile_box --exhaustive
--no-search --jobs 1`, what docs/compiled.md reports).

    python benchmarks/check_blocks.py [ROUTINE ...] [--against REV] [--set]

REV (default 43b5b3b: main where this work began) is written out with `git archive` into a temporary folder;
both trees share the compiled-code and assembler caches (~/.cache/retro), so neither compiles.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from compiled_speed import ISSUE_SET, _child_cpu  # (the issue's set, and the children's CPU, defined there)

ROOT = Path(__file__).resolve().parents[1]
ROUTINES = ["circle", "circle_r", "tile_box", "aabb_sprite"]
ROUNDS = 3
BASE = "43b5b3b"  # main where this work began

# Run inside each tree (PYTHONPATH): prints one JSON line of CPU seconds.
IN_TREE = """
import json, sys, time
from retro.analysis.check import run as R
from retro.analysis.check.engines import run_on_batched_core, runner_for
from retro.analysis.check.tally import count_array_block
from retro.routines import cases as case_sets
from retro.routines.registry import select

name, rounds = sys.argv[1], int(sys.argv[2])
spec = select([name])[0]
R.check_routine(spec, exhaustive=True, search_budget=0)
clock = time.process_time
checks = []
for _ in range(rounds):
    began = clock()
    R.check_routine(spec, exhaustive=True, search_budget=0)
    checks.append(clock() - began)
plan = R._planned(spec, True, None, None, case_sets.BOUNDED_PRODUCT)
runner = runner_for(plan.spec, plan.seed, None)
engine = R._engine_choice(plan, runner, "auto", None).used
sweep = R.Sweep(plan.spec, plan.seed, True, plan.random, case_sets.BOUNDED_PRODUCT, engine)
R._PLANS[sweep] = plan.parts
spent = {"making": [], "engine": [], "tally": []}
for _ in range(rounds):
    totals = dict.fromkeys(spent, 0.0)
    blocks = case_sets.stream(plan.parts, sweep.block, 0, sweep.counted)
    count = 0
    while True:
        began = clock()
        block = next(blocks, None)
        totals["making"] += clock() - began
        if block is None:
            break
        count += 1
        began = clock()
        calls = run_on_batched_core(runner, block, engine=engine)
        totals["engine"] += clock() - began
        began = clock()
        count_array_block(runner.routine, calls, block, runner.memory_values)
        totals["tally"] += clock() - began
    for key in spent:
        spent[key].append(totals[key] / max(count, 1))
print(json.dumps({"check": min(checks), "engine_used": engine, "blocks": count,
                  **{key: min(values) for key, values in spent.items()}}))
"""


BYTECODE = Path(tempfile.gettempdir()) / "retro-blocks-bytecode"  # PYTHONPYCACHEPREFIX of both trees' runs


def _environment(tree: Path) -> dict:
    """The tree's modules first, and one bytecode cache for both trees' runs, written (under BYTECODE), never
    a tree's own __pycache__: a working tree keeps the .pyc files of earlier runs and an archived one has
    none, so with PYTHONDONTWRITEBYTECODE set (this machine) one tree's start would pay for compiling its
    sources and the other's not. Each figure is a best of ROUNDS: the first run of each tree fills it."""
    environment = {**os.environ, "PYTHONPATH": str(tree), "PYTHONPYCACHEPREFIX": str(BYTECODE)}
    environment.pop("PYTHONDONTWRITEBYTECODE", None)
    return environment


def _in_tree(tree: Path, name: str) -> dict:
    done = subprocess.run([sys.executable, "-c", IN_TREE, name, "1"], capture_output=True, text=True, cwd=tree,
                          env=_environment(tree))
    if done.returncode:
        sys.exit(f"check_blocks: {name} in {tree}: {done.stderr.strip()[-400:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _process(tree: Path, arguments: list[str]) -> float:
    before = _child_cpu()
    done = subprocess.run([sys.executable, "-m", "retro", *arguments], capture_output=True, text=True, cwd=tree,
                          env=_environment(tree))
    if done.returncode not in (0, 1):
        sys.exit(f"check_blocks: retro {' '.join(arguments)} in {tree}: {done.stderr.strip()[-400:]}")
    return _child_cpu() - before


def _load() -> str:
    return f"load {os.getloadavg()[0]:.1f}"


def routines(names: list[str], trees: dict[str, Path]) -> None:
    for name in names:
        runs = {label: [] for label in trees}
        for _ in range(ROUNDS):
            for label, tree in trees.items():
                runs[label].append(_in_tree(tree, name))
        best = {label: {key: min(r[key] for r in rows) for key in ("check", "making", "engine", "tally")}
                for label, rows in runs.items()}
        blocks = runs[next(iter(trees))][0]["blocks"]
        line = " | ".join(f"{label}: check {b['check']:.3f} s, a block: making {b['making'] * 1e3:.3f} ms, engine "
                          f"{b['engine'] * 1e3:.3f}, tally {b['tally'] * 1e3:.3f}" for label, b in best.items())
        ratio = ""
        if len(trees) == 2:
            old, new = best.values()
            ratio = f" ({old['check'] / new['check']:.2f}x the check)"
        print(f"{name} ({blocks} blocks, {runs[next(iter(trees))][0]['engine_used']}), {_load()}: {line}{ratio}",
              flush=True)


def processes(commands: dict[str, list[str]], trees: dict[str, Path], rounds: int = ROUNDS) -> None:
    for title, arguments in commands.items():
        spent = {label: [] for label in trees}
        for _ in range(rounds):
            for label, tree in trees.items():
                spent[label].append(_process(tree, arguments))
        best = {label: min(values) for label, values in spent.items()}
        ratio = f" ({list(best.values())[0] / list(best.values())[1]:.2f}x)" if len(trees) == 2 else ""
        print(f"{title}, {_load()}, CPU s best of {rounds}: "
              + ", ".join(f"{label} {seconds:.2f}" for label, seconds in best.items()) + ratio, flush=True)


def main(argv: list[str]) -> None:
    against = BASE
    if "--against" in argv:
        at = argv.index("--against")
        against = argv[at + 1]
        argv = argv[:at] + argv[at + 2:]
    whole_set = "--set" in argv
    names = [a for a in argv if a != "--set"] or ROUTINES
    with tempfile.TemporaryDirectory(prefix="retro-blocks-") as folder:
        old = Path(folder) / "tree"
        old.mkdir()
        archive = subprocess.run(["git", "archive", against], cwd=ROOT, capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", str(old)], input=archive, check=True)
        trees = {against: old, "this tree": ROOT}
        routines(names, trees)
        processes({"retro check --help": ["check", "--help"], "retro check mul8": ["check", "mul8", "--json"]}, trees)
        if whole_set:
            processes({"the issue's set in one process": ["check", *ISSUE_SET, "--exhaustive", "--no-search",
                                                          "--jobs", "1", "--json"]}, trees, rounds=2)


if __name__ == "__main__":
    main(sys.argv[1:])
