"""How long the long commands take to stop after Ctrl-C (or SIGTERM), and whether a worker is left.

Each command is started as `python -m retro ...`, sent the signal after a delay (during the imports,
then at points of its run), and timed from the signal to the process's end; its worker processes
(listed just before the signal) must all be gone. Prints one row per run and the worst latency per
command (docs/files.md has a run's figures).

    python benchmarks/ctrl_c_latency.py [--quick]
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _children(pid: int) -> list[int]:
    listed = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True).stdout
    return [int(n) for n in listed.split()]


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().split(") ")[1][0] != "Z"
    except OSError:
        return False


def stop(args: list[str], delay: float, signum: int = signal.SIGINT) -> tuple[float, int, int, int, str]:
    """(seconds from the signal to the end, exit code, workers seen, workers left, last stderr line)."""
    child = subprocess.Popen([sys.executable, "-m", "retro", *args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    time.sleep(delay)
    workers = _children(child.pid)
    start = time.monotonic()
    child.send_signal(signum)
    _, err = child.communicate(timeout=120)
    seconds = time.monotonic() - start
    time.sleep(0.2)
    left = sum(_alive(pid) for pid in workers)
    last = err.strip().splitlines()[-1] if err.strip() else ""
    return seconds, child.returncode, len(workers), left, last


def main() -> None:
    quick = "--quick" in sys.argv
    out = tempfile.mkdtemp(prefix="retro-ctrl-c-")
    commands = {
        "chart (full, --jobs 2)": ["chart", "--quiet", "--out", f"{out}/chart"],
        "check --exhaustive (--jobs 2)": ["check", "--exhaustive", "--quiet"],
        "check --exhaustive --jobs 1": ["check", "--exhaustive", "--quiet", "--jobs", "1"],
        "stability (full)": ["stability", "--quiet", "--out", f"{out}/stability"],
    }
    delays = (0.3, 3.0, 10.0) if quick else (0.1, 0.3, 0.6, 1.0, 3.0, 6.0, 10.0, 20.0)
    print(f"{'command':32s} {'signal':8s} {'after':>6s} {'stopped in':>10s} {'exit':>4s} {'workers':>7s} {'left':>4s}  line")
    for name, args in commands.items():
        worst = 0.0
        for delay in delays:
            for signum in ((signal.SIGINT,) if delay != delays[-1] else (signal.SIGINT, signal.SIGTERM)):
                seconds, code, workers, left, last = stop(args, delay, signum)
                worst = max(worst, seconds)
                print(f"{name:32s} {signal.Signals(signum).name:8s} {delay:5.1f}s {seconds:9.2f}s {code:4d} "
                      f"{workers:7d} {left:4d}  {last}")
        print(f"{name}: worst {worst:.2f} s")


if __name__ == "__main__":
    main()
