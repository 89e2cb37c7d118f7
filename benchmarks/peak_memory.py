"""Peak memory of every command at its documented limits: the resident memory of the whole process
tree (the command and its worker processes, summed), sampled every 50 ms from /proc.

A command whose limit is a count of work (check --random 1,000,000,000) would run for hours; it is
stopped after --seconds (default 60) and its peak so far is reported with "stopped": those commands
make their work in bounded blocks, so the peak is reached in the first blocks (the table in
docs/limits.md says which rows were stopped). Outputs go to a temporary folder.

    PYTHONPATH=. python benchmarks/peak_memory.py [--seconds S] [--only NAME ...]
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GIB = 1 << 30
PAGE = os.sysconf("SC_PAGE_SIZE")
SAMPLE_SECONDS = 0.05


def commands(out: Path) -> list[tuple[str, list[str], str]]:
    """(name, arguments of `retro`, what limit it exercises)."""
    spec = ROOT / "tests" / "data" / "specs" / "boxhit_acme.toml"
    big = out / "generator"
    big.mkdir(exist_ok=True)
    (big / "refs.py").write_text("import numpy as np\ndef ref(a):\n    return a\n"
                                 "def table(rng):\n    return np.ones(1 << 28, dtype=np.uint8)\n")
    (big / "r.s").write_text("        .org $c000\nentry:\n        rts\n")
    (big / "spec.toml").write_text('[program]\nfile = "r.s"\nentry = "entry"\n[inputs]\na = "A"\n[outputs]\nr = "A"\n'
                                   '[memory]\nt = { at = "$2000", generator = "refs.py:table" }\n'
                                   '[reference]\nfunction = "refs.py:ref"\n[cases]\nrandom = 10\n')
    hog = out / "hog"
    hog.mkdir(exist_ok=True)
    (hog / "r.s").write_text((big / "r.s").read_text())
    (hog / "refs.py").write_text("def ref(a):\n    return len([0] * (1 << 28))\n")
    (hog / "spec.toml").write_text((big / "spec.toml").read_text().replace(
        '[memory]\nt = { at = "$2000", generator = "refs.py:table" }\n', ""))
    where = out / "where"
    where.mkdir(exist_ok=True)
    for name in ("refs.py", "r.s"):
        (where / name).write_text((big / name).read_text())
    (where / "spec.toml").write_text((big / "spec.toml").read_text().replace(
        '[memory]\nt = { at = "$2000", generator = "refs.py:table" }\n', "").replace(
        "random = 10", 'random = 10\nwhere = "len([0] * (1 << 28)) > 0"'))
    loop = out / "loop.s"
    loop.write_text("        .org $c000\nentry:  jmp entry\n")
    scene = ROOT / "examples" / "vic_two_balls.toml"
    moving = out / "moving.toml"  # every sprite moves: each of the 10,000 frames is a collision pass
    moving.write_text(scene.read_text().replace('"../sprites/', f'"{ROOT / "sprites"}/').replace(
        "[[sprite]]\n", "[[sprite]]\nvelocity = [1, 1]\n"))
    nes_scene = next(iter(sorted((ROOT / "examples").glob("nes*.toml"))), scene)
    return [
        ("asm", ["asm", str(ROOT / "asm" / "aabb8.s"), "-o", str(out / "a.prg"), "--labels", str(out / "a.lbl")],
         "a built-in source"),
        ("run", ["run", str(loop), "--entry", "entry", "--budget", "100000000"],
         "an endless loop, --budget 100,000,000"),
        ("run-trace", ["run", str(loop), "--entry", "entry", "--budget", "100000000", "--trace"],
         "an endless loop, --budget 100,000,000 --trace"),
        ("vic", ["vic", str(moving), "--frames", "10000", "--scale", "8", "--png", str(out / "v.png")],
         "four moving sprites, --frames 10,000 --scale 8 --png"),
        ("nes", ["nes", str(nes_scene), "--scale", "16", "--png", str(out / "n.png")], "--scale 16 --png"),
        ("check-pixel", ["check", "pixel", "--exhaustive", "--jobs", "2", "--quiet"], "pixel --exhaustive --jobs 2 (table inputs, sweeps)"),
        ("check", ["check", str(spec), "--random", "1000000000", "--jobs", "2", "--quiet"],
         "--random 10^9 --jobs 2 (batched core)"),
        ("check-scalar", ["check", str(spec), "--random", "1000000000", "--jobs", "2", "--engine", "scalar", "--quiet"],
         "--random 10^9 --jobs 2 --engine scalar"),
        ("check-generator", ["check", str(big / "spec.toml"), "--jobs", "1"], "a [memory] generator of 256 MB"),
        ("check-hog", ["check", str(hog / "spec.toml"), "--jobs", "1"],
         "a reference that builds [0] * (1 << 28): 2 GiB"),
        ("check-where", ["check", str(where / "spec.toml"), "--jobs", "1"], "where = len([0] * (1 << 28)) > 0"),
        ("cycles", ["cycles", "--jobs", "2", "--quiet"], "every built-in routine, --jobs 2"),
        ("chart", ["chart", "--samples", "1000000", "--jobs", "2", "--per-frame", "--quiet", "--out", str(out / "c")],
         "--samples 1,000,000 --jobs 2 --per-frame"),
        ("stability", ["stability", "--quiet", "--out", str(out / "s")], "the full run"),
        ("advise", ["advise", str(scene), "--objects", "64", "--jobs", "2", "--quiet"], "--objects 64 --jobs 2"),
        ("parry", ["parry", "--frames", "2000", "--out", str(out / "p")], "--frames 2,000"),
        ("demo", ["demo", "--out", str(out / "d")], "every example"),
    ]


def process_tree(root: int) -> list[int]:
    """A process and all its descendants (from /proc/*/stat)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat", "rb") as f:
                    parent = int(f.read().rsplit(b")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(parent, []).append(int(entry))
    found, stack = [], [root]
    while stack:
        pid = stack.pop()
        found.append(pid)
        stack.extend(children.get(pid, []))
    return found


def process_rss(pid: int) -> int:
    """Resident bytes of one process (0: gone)."""
    try:
        with open(f"/proc/{pid}/statm", "rb") as f:
            return int(f.read().split()[1]) * PAGE
    except (OSError, IndexError, ValueError):
        return 0


def tree_rss(root: int) -> int:
    """Resident bytes of a process and all its descendants."""
    return sum(process_rss(pid) for pid in process_tree(root))


TICKS = os.sysconf("SC_CLK_TCK")


def process_cpu(pid: int) -> float | None:
    """CPU seconds (user + system) of one process so far (None: gone)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / TICKS
    except (OSError, IndexError, ValueError):
        return None


@dataclass(frozen=True)
class SampledRun:
    """A command run to its end, its process tree sampled from /proc while it ran."""

    returncode: int
    stdout: str
    wall: float  # seconds
    cpu: float  # CPU seconds of every process of the tree, each as last sampled (a worker that is stopped,
    # not waited for, is missed by the rusage of children; at most `every` of a process's last moments are lost)
    peak: int  # the largest RSS of any one process of the tree (bytes)
    peak_tree: int  # the largest RSS of the whole tree at once (bytes)


def sampled_run(command: list[str], every: float = 0.5) -> SampledRun:
    """Run `command` (stderr dropped) sampling its process tree's CPU and RSS every `every` seconds."""
    began = time.monotonic()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                               env={**os.environ, "PYTHONPATH": str(ROOT)})
    peak = peak_tree = 0
    spent: dict[int, float] = {}
    while process.poll() is None:
        tree = [(pid, process_rss(pid)) for pid in process_tree(process.pid)]
        peak = max([peak] + [rss for _, rss in tree])
        peak_tree = max(peak_tree, sum(rss for _, rss in tree))
        for pid, _ in tree:
            seconds = process_cpu(pid)
            if seconds is not None:
                spent[pid] = seconds
        time.sleep(every)
    out = process.stdout.read()
    return SampledRun(process.returncode, out, time.monotonic() - began, sum(spent.values()), peak, peak_tree)


def spec_with_sweep(spec: Path, folder: Path, sweep_module: str) -> Path:
    """A copy of a built-in spec in `folder` whose sweep is `sweep()` of `sweep_module` (Python source,
    written beside it as slice.py), its program read from the spec's own folder: a bounded slice of a
    proof for the sweep benchmarks."""
    text = spec.read_text()
    program = re.search(r'^file = "([^"]+)"', text, re.MULTILINE).group(1)
    text = text.replace(f'file = "{program}"', f'file = "{(spec.parent / program).as_posix()}"')
    text = re.sub(r'^sweep = "[^"]+"', 'sweep = "slice.py:sweep"', text, count=1, flags=re.MULTILINE)
    (folder / "slice.py").write_text(sweep_module)
    copy = folder / f"{spec.stem}_slice.toml"
    copy.write_text(text)
    return copy


def measure(arguments: list[str], seconds: float) -> tuple[int, float, str]:
    """(peak bytes of the tree, seconds, how it ended: "exit N" or "stopped")."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    process = subprocess.Popen([sys.executable, "-m", "retro", *arguments], stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, env=env, start_new_session=True)
    start = time.monotonic()
    peak = 0
    while process.poll() is None:
        peak = max(peak, tree_rss(process.pid))
        if time.monotonic() - start > seconds:
            os.killpg(process.pid, signal.SIGTERM)
            process.wait()
            return peak, time.monotonic() - start, "stopped"
        time.sleep(SAMPLE_SECONDS)
    error = process.stderr.read().decode(errors="replace").strip().splitlines()
    ending = f"exit {process.returncode}" + (f": {error[-1][:70]}" if error and process.returncode else "")
    return peak, time.monotonic() - start, ending


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--only", nargs="*")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        print(f"| command | at its limits | peak RSS (tree) | time | ended |")
        print("|---|---|---:|---:|---|")
        for name, arguments, limit in commands(Path(folder)):
            if args.only and name not in args.only:
                continue
            peak, took, ending = measure(arguments, args.seconds)
            flag = "" if peak < GIB else " **over 1 GiB**"
            print(f"| {name} | {limit} | {peak / (1 << 20):,.0f} MiB{flag} | {took:.0f} s | {ending} |", flush=True)


if __name__ == "__main__":
    main()
