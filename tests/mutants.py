"""Mutation testing: named one-line changes to the rules of the CPU, the chips and the checker; each
must make a test fail ("killed"). Run: `python tests/mutants.py [NAME ...] [--list]`.

Every mutant is applied to a private copy of the tree (so other work in the checkout is never
disturbed), then the tests that guard its rule run against that copy. A mutant that survives is a
rule no test can see: docs/mutation.md lists the last run and explains every survivor.
Exit status: 0 when every mutant was killed or is explained, 1 otherwise.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT_SECONDS = 900


@dataclass(frozen=True)
class Mutant:
    name: str
    file: str
    old: str  # must occur exactly once in the file
    new: str
    tests: tuple[str, ...]
    explained: str = ""  # why a survivor is acceptable (empty: it must be killed)


VIC_TESTS = ("tests/vic",)
CPU_TESTS = ("tests/cpu",)
BATCH_TESTS = ("tests/cpu/test_batch_vectors.py", "tests/routines/test_batch_check.py")
CHECK_TESTS = ("tests/routines/test_user_specs.py", "tests/routines/test_routines_cli.py",
               "tests/routines/test_routines_exhaustive.py")

MUTANTS = [
    # ---- VIC-II --------------------------------------------------------------------------------
    Mutant("d01f-not-cleared-on-read", "retro/chips/vic/device.py",
           "value, self.sprite_background = self.sprite_background, 0",
           "value = self.sprite_background", VIC_TESTS),
    Mutant("d01e-not-cleared-on-read", "retro/chips/vic/device.py",
           "value, self.sprite_sprite = self.sprite_sprite, 0",
           "value = self.sprite_sprite", VIC_TESTS),
    Mutant("d019-bit1-latches-on-every-event", "retro/chips/vic/device.py",
           "if new_sb and not self.sprite_background:", "if new_sb:", VIC_TESTS),
    Mutant("d019-bit2-latches-on-every-event", "retro/chips/vic/device.py",
           "if new_ss and not self.sprite_sprite:", "if new_ss:", VIC_TESTS),
    Mutant("line0-raster-delay-zero", "retro/chips/vic/constants.py",
           "RASTER_IRQ_LINE0_DELAY = 1", "RASTER_IRQ_LINE0_DELAY = 0", VIC_TESTS),
    Mutant("register-write-same-cycle", "retro/chips/vic/device.py",
           "self._advance(t + 1)  # what is drawn up to and including this cycle used the old value",
           "self._advance(t)", VIC_TESTS),
    Mutant("collision-latch-delay", "retro/chips/vic/constants.py",
           "COLLISION_LATCH_DELAY = 4", "COLLISION_LATCH_DELAY = 3", VIC_TESTS),
    Mutant("d019-ack-ignored", "retro/chips/vic/device.py",
           "self.irq_latch &= ~value & IRQ_SOURCES", "self.irq_latch &= IRQ_SOURCES", VIC_TESTS),
    # ---- CPU -------------------------------------------------------------------------------------
    Mutant("branch-taken-costs-nothing", "retro/cpu/timing.py",
           "BRANCH_TAKEN_CYCLES = 1", "BRANCH_TAKEN_CYCLES = 0", CPU_TESTS + ("tests/routines/test_routines_timing.py",)),
    Mutant("page-cross-costs-nothing", "retro/cpu/timing.py",
           "PAGE_CROSS_CYCLES = 1", "PAGE_CROSS_CYCLES = 0", CPU_TESTS + ("tests/routines/test_routines_timing.py",)),
    Mutant("jsr-cycles", "retro/cpu/machine.py",
           "JSR_CYCLES = 6  # the caller's JSR", "JSR_CYCLES = 5  # the caller's JSR", CPU_TESTS + ("tests/test_cli_foundation.py",)),
    Mutant("default-flags-without-i", "retro/cpu/machine.py",
           "DEFAULT_FLAGS = FLAG_U | FLAG_I", "DEFAULT_FLAGS = FLAG_U", CPU_TESTS + ("tests/routines/test_user_specs.py",)),
    # ---- the checker -----------------------------------------------------------------------------
    Mutant("cycle-mismatches-not-counted", "retro/analysis/check.py",
           "            out.cycle_mismatches += 1\n", "            pass\n", CHECK_TESTS),
    Mutant("static-bound-violations-ignored", "retro/analysis/check.py",
           "if static is not None and t.cycles_count and t.cpu_max > static.worst:",
           "if False:", CHECK_TESTS),
    Mutant("static-min-violations-ignored", "retro/analysis/check.py",
           "if static is not None and t.cycles_count and t.cpu_min < static.best:",
           "if False:", CHECK_TESTS),
    Mutant("budget-not-checked", "retro/analysis/check.py",
           "if t.cycles_count and t.cycles_max > routine.budget:", "if False:", CHECK_TESTS),
    Mutant("static-budget-not-checked", "retro/analysis/check.py",
           "if static is not None and static.worst > routine.budget:", "if False:", CHECK_TESTS),
    Mutant("outside-domain-counted-as-inside", "retro/analysis/check.py",
           "        if broken:\n            out.outside += 1", "        if False:\n            out.outside += 1",
           CHECK_TESTS),
    Mutant("result-mismatch-not-counted", "retro/analysis/check.py",
           "            out.result_mismatches += 1\n", "            pass\n", CHECK_TESTS),
    Mutant("run-error-not-stopping", "retro/analysis/check.py",
           "            break  # a broken routine stops the check", "            continue  # a broken routine stops the check",
           CHECK_TESTS),
    Mutant("stalls-counted-as-cpu-cycles", "retro/analysis/check.py",
           "cpu_cycles = cycles - runner.last_stolen", "cpu_cycles = cycles", CHECK_TESTS),
    # ---- routine specs and static analysis -------------------------------------------------------
    Mutant("jsr-callee-cost-dropped", "retro/cpu/flow.py",
           "node.cycles = (op.cycles + best, op.cycles + worst)", "node.cycles = (op.cycles, op.cycles)",
           CHECK_TESTS),
    Mutant("flag-input-ignored", "retro/routines/runner.py",
           "            if case[index]:\n                p |= bit", "            if False:\n                p |= bit",
           ("tests/routines",)),
    Mutant("high-byte-of-output-dropped", "retro/routines/runner.py",
           "value |= byte << (8 * shift)", "value |= byte if shift == 0 else 0", ("tests/routines",)),
    # ---- the batched core and its checks --------------------------------------------------------
    Mutant("batch-branch-page-costs-nothing", "retro/cpu/batch.py",
           "extra = extra_taken + crossed * BRANCH_PAGE_CYCLES", "extra = extra_taken", BATCH_TESTS),
    Mutant("batch-page-cross-costs-nothing", "retro/cpu/batch.py",
           "if penalised and crossed is not False:", "if False:", BATCH_TESTS),
    Mutant("batch-decimal-high-adjust-off-by-one", "retro/cpu/batch.py",
           "high = np.where(high >= 0xA0, high + 0x60, high)", "high = np.where(high >= 0xA1, high + 0x60, high)",
           BATCH_TESTS),
    Mutant("batch-rts-without-plus-one", "retro/cpu/batch.py",
           "return _uniform(((g.pull() << 8 | low) + 1) & WORD)", "return _uniform((g.pull() << 8 | low) & WORD)",
           BATCH_TESTS),
    Mutant("batch-lane-rows-ignored-on-read", "retro/cpu/batch.py",
           "            row = self.rows.get(int(address))\n            if row is None:",
           "            row = None\n            if row is None:", BATCH_TESTS),
    Mutant("batch-result-mismatches-not-counted", "retro/analysis/check.py",
           "out.result_mismatches = len(wrong_inside)", "out.result_mismatches = 0", BATCH_TESTS),
    Mutant("engine-disagreement-not-counted", "retro/analysis/check.py",
           "found += self.agreement.engine_mismatches + self.agreement.cycle_mismatches", "found += 0",
           BATCH_TESTS),
    Mutant("agreement-run-skipped", "retro/analysis/check.py",
           "agreement.merge(agreement_chunk(spec, seed, chunk))", "pass", BATCH_TESTS),
]


def copy_tree(destination: Path) -> Path:
    ignore = shutil.ignore_patterns(".git", ".venv", "v", "build", "*.egg-info", "__pycache__", ".pytest_cache",
                                    ".hypothesis", "retro-out", "out")
    shutil.copytree(ROOT, destination, ignore=ignore)
    return destination


def run_mutant(mutant: Mutant, tree: Path) -> tuple[str, float]:
    path = tree / mutant.file
    original = path.read_text()
    if original.count(mutant.old) != 1:
        return f"STALE (the text to change occurs {original.count(mutant.old)} times)", 0.0
    path.write_text(original.replace(mutant.old, mutant.new))
    started = time.monotonic()
    try:
        env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1",
               "RETRO_CPU_VECTORS": os.environ.get("RETRO_CPU_VECTORS", str(ROOT.parent / "shared" / "cpu-vectors"))}
        done = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *mutant.tests],
                              cwd=tree, env=env, capture_output=True, text=True, timeout=TIMEOUT_SECONDS)
        failed = [line.split(" ", 2)[1] for line in done.stdout.splitlines() if line.startswith(("FAILED ", "ERROR "))]
        verdict = (f"killed by {failed[0].split('::')[-1][:60]}" if failed else "killed") if done.returncode else "SURVIVED"
    except subprocess.TimeoutExpired:
        verdict = "killed (timeout)"
    finally:
        path.write_text(original)
    return verdict, time.monotonic() - started


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("names", nargs="*", help="mutants to run (default: all)")
    parser.add_argument("--list", action="store_true", help="list the mutants and exit")
    args = parser.parse_args(argv)
    chosen = [m for m in MUTANTS if not args.names or m.name in args.names]
    if args.list:
        for m in MUTANTS:
            print(f"{m.name:36} {m.file}")
        return 0
    unknown = set(args.names) - {m.name for m in MUTANTS}
    if unknown:
        print(f"mutants: unknown mutant {sorted(unknown)[0]!r} (see --list)", file=sys.stderr)
        return 2
    failures = 0
    with tempfile.TemporaryDirectory(prefix="retro-mutants-") as tmp:
        tree = copy_tree(Path(tmp) / "tree")
        print("| mutant | file | verdict | seconds |\n|---|---|---|---|", flush=True)
        for mutant in chosen:
            verdict, seconds = run_mutant(mutant, tree)
            if verdict == "SURVIVED" and mutant.explained:
                verdict = f"survived, explained: {mutant.explained}"
            elif not verdict.startswith("killed"):
                failures += 1
            print(f"| {mutant.name} | {mutant.file} | {verdict} | {seconds:.0f} |", flush=True)
    killed = len(chosen) - failures
    print(f"\n{killed} of {len(chosen)} mutants killed or explained; {failures} not")
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
