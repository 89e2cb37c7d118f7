"""aabb8 over every input of each axis (3 x 2^32 calls, `retro check aabb8 --exhaustive`): a slice of it
measured, the whole extrapolated (issue 24: under 3 minutes on 2 cores; at most 1 GiB of RSS per worker).

The slice is the same sweep with box A's position taken from the first K values instead of all 256
(3 x K x 2^24 calls: K = 16 is 3 x 2^28), run by `retro check --exhaustive --engine ENGINE --jobs J
--no-search` on a copy of the spec. Printed: wall and CPU seconds of the whole process tree (the
workers included, sampled from /proc), calls per CPU-second, the largest RSS of any one process of the tree (sampled),
and the full sweep's time extrapolated from the slice's rate (the boundary and random cases and the
start-up are in the slice's time: the extrapolation is on the safe side).

    python benchmarks/aabb8_sweep.py [K] [--jobs J] [--engine compiled|batch]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from peak_memory import process_rss, process_tree  # benchmarks/: the script's own folder

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "asm" / "aabb8.toml"
FULL_CALLS = 3 << 32
SAMPLE_SECONDS = 0.5
GOAL_SECONDS = 180  # the issue's: under 3 minutes on 2 cores
GOAL_RSS = 1 << 30  # per worker
TICKS = os.sysconf("SC_CLK_TCK")


def _cpu(pid: int) -> float | None:
    """CPU seconds (user + system) of one process so far (None: gone)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / TICKS
    except (OSError, IndexError, ValueError):
        return None


def sliced_spec(folder: Path, starts: int) -> Path:
    text = SPEC.read_text()
    text = text.replace('file = "aabb8.s"', f'file = "{(SPEC.parent / "aabb8.s").as_posix()}"')
    text = text.replace('sweep = "retro.routines.builtin_cases:aabb8_sweep"', 'sweep = "slice.py:sweep"')
    (folder / "slice.py").write_text("from retro.routines.builtin_cases import aabb8_sweep\n\n\n"
                                     f"def sweep():\n    return aabb8_sweep(range({starts}))\n")
    spec = folder / "aabb8_slice.toml"
    spec.write_text(text)
    return spec


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("starts", nargs="?", type=int, default=16)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--engine", default="compiled")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        spec = sliced_spec(Path(folder), args.starts)
        began = time.monotonic()
        process = subprocess.Popen([sys.executable, "-m", "retro", "check", str(spec), "--exhaustive", "--engine",
                                    args.engine, "--jobs", str(args.jobs), "--no-search", "--json"],
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                                   env={**os.environ, "PYTHONPATH": str(ROOT)})
        peak, spent = 0, {}
        while process.poll() is None:
            for pid in process_tree(process.pid):
                peak = max(peak, process_rss(pid))
                seconds = _cpu(pid)
                if seconds is not None:
                    spent[pid] = seconds
            time.sleep(SAMPLE_SECONDS)
        out = process.stdout.read()
        wall = time.monotonic() - began
    # each process's CPU as last sampled (a worker is stopped, not waited for, so the rusage of
    # children misses it): at most SAMPLE_SECONDS of a process's last moments are left out
    cpu = sum(spent.values())
    record = json.loads(out)[0] if out.strip() else {}
    calls = record.get("cases", 0)
    swept = 3 * args.starts << 24
    rate = calls / cpu if cpu else 0.0
    full_cpu = FULL_CALLS / rate if rate else float("inf")
    print(f"aabb8 slice: box A's position from {args.starts} of 256 values: {swept:,} sweep calls "
          f"(2^{swept.bit_length() - 1}), {calls:,} calls in all, exit {process.returncode}, "
          f"mismatches {record.get('mismatches', '?')}")
    print(f"  --engine {args.engine} --jobs {args.jobs}: {wall:.1f} s wall, {cpu:.1f} CPU s, "
          f"{rate / 1e6:.1f} M calls per CPU-second; largest process RSS {peak / 2**20:.0f} MiB "
          f"(goal: under {GOAL_RSS >> 20} MiB per worker)")
    print(f"  the full sweep (3 x 2^32 calls) at that rate: {full_cpu:,.0f} CPU s, about "
          f"{full_cpu / args.jobs / 60:.1f} min on {args.jobs} cores (goal: under {GOAL_SECONDS / 60:.0f} min)")


if __name__ == "__main__":
    main(sys.argv[1:])
