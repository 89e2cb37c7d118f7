"""Record (or compare) the JSON of `retro check` and `retro cycles` for every built-in routine, every
example and test spec, on each engine, with and without a VIC-II scene, and for checks that fail in
each way (a wrong result inside and outside the domain, a broken budget, BRK, JAM, a runaway call).

The golden files in tests/golden/check/ were recorded from main at d1bc2f2 (64be42f plus the work
merged before it), before the refactor of issue 21, so tests/test_check_golden.py compares the
checker against its own earlier output:

    python tests/golden/make_check_golden.py           # record (only before a change of behaviour)
    python tests/golden/make_check_golden.py --compare # what the test does, as a script

Each run is the real command line (`python -m retro ... --json --quiet` in a fresh interpreter), so
exit codes are recorded too. The recordings predate the coverage-guided search, which adds cases (and
may find new extremes): each run says --no-search, so they still compare like with like (the search
is tested in tests/routines/test_code_coverage.py). The check's JSON has no timing fields; the only field that depends on
where it runs is the absolute path of the checkout (built-in specs are named by absolute path, and
messages may quote it), replaced by "<repo>" in every string.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = Path(__file__).resolve().parent / "check"
RECORDED_FROM = "d1bc2f2"
ENGINES = ("auto", "scalar", "batch")

USER_SPECS = (sorted(str(p.relative_to(ROOT)) for p in (ROOT / "tests/data/specs").glob("boxhit_*.toml"))
              + ["tests/data/specs/scan/scan.toml", "examples/boxhit/boxhit.toml"])
FAILING_SPECS = [f"tests/golden/specs/{name}.toml" for name in ("outside", "outside_arrays", "brk", "jam", "spin")]
SCENE = "examples/vic_two_balls.toml"
RECORDED_BUILTINS = ("aabb8", "aabb_edges", "aabb_edges_prepare", "aabb_sprite", "circle", "circle_r", "circle_r_prepare",
                     "mul8", "pixel", "sprite_edges", "sprite_edges_prepare", "tile", "tile_box")
# the built-in routines when the recording was made, named on the command lines (it ran `retro check` with
# no names: all of them); a built-in added later (mul16) is held to its reference and to the other
# engines (tests/routines/test_compiled_check.py), not to a recording of its own output


def cases() -> dict[str, list[str]]:
    """Name -> the command line after `retro`."""
    out: dict[str, list[str]] = {}
    for engine in ENGINES:
        out[f"builtins-{engine}"] = ["check", "--engine", engine, *RECORDED_BUILTINS]
        out[f"user-specs-{engine}"] = ["check", "--engine", engine, *USER_SPECS]
    for spec in FAILING_SPECS:
        for engine in ("scalar", "batch"):
            out[f"{Path(spec).stem}-{engine}"] = ["check", "--engine", engine, spec]
    out["cycles-builtins"] = ["cycles", *RECORDED_BUILTINS]
    out["cycles-user-specs-batch"] = ["cycles", "--engine", "batch", *USER_SPECS]
    out["builtins-seed-random"] = ["check", "--seed", "5", "--random", "300", "aabb8", "circle", "tile", "mul8"]
    out["scene"] = ["check", "--scene", SCENE, "aabb8", "mul8", "tile", "examples/boxhit/boxhit.toml"]
    out["scene-at"] = ["check", "--scene", SCENE, "--at-line", "48", "--at-cycle", "5", "aabb8", "circle_r"]
    # (pixel's masks at $D100 were here too: a VIC-II register mirror, now an error naming both)
    out["cycles-scene"] = ["cycles", "--scene", SCENE, "--at-line", "100", "sprite_edges"]
    out["scene-failing"] = ["check", "--scene", SCENE, "tests/golden/specs/outside.toml"]
    return out


def normalise(value):
    if isinstance(value, str):
        return value.replace(str(ROOT), "<repo>")
    if isinstance(value, list):
        return [normalise(v) for v in value]
    if isinstance(value, dict):
        return {k: normalise(v) for k, v in value.items()}
    return value


def run(args: list[str], root: Path = ROOT) -> dict:
    """One command line's exit code and JSON, normalised."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    done = subprocess.run([sys.executable, "-m", "retro", *args, "--no-search", "--json", "--quiet"], cwd=root, env=env,
                          capture_output=True, text=True, timeout=600)
    try:
        output = json.loads(done.stdout)
    except json.JSONDecodeError:
        raise AssertionError(f"retro {' '.join(args)}: no JSON (exit {done.returncode}): {done.stderr[-500:]}") from None
    return {"args": args, "exit": done.returncode, "json": normalise(output)}


def golden_path(name: str) -> Path:
    return GOLDEN / f"{name}.json"


def main(argv: list[str]) -> int:
    compare = "--compare" in argv
    GOLDEN.mkdir(exist_ok=True)
    differ = []
    for name, args in cases().items():
        got = run(args)
        if compare:
            if json.loads(golden_path(name).read_text()) != got:
                differ.append(name)
            continue
        golden_path(name).write_text(json.dumps(got, indent=1, sort_keys=True) + "\n")
        print(f"{name}: exit {got['exit']}, {len(got['json'])} routine(s)")
    if compare:
        print("differ: " + (", ".join(differ) or "none"))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
