"""Mutation testing: named one-line changes to the rules of the CPU, the chips, the raster budget, the checker, the
stability study, the field toolkit and the commands; each must make a test fail ("killed").
Run: `python tests/mutants.py [NAME ...] [--list]`.

Every mutant is applied to a private copy of the tree (so other work in the checkout is never
disturbed), then the tests that guard its rule run against that copy. A mutant that survives is a
rule no test can see: docs/mutation.md lists the last run and explains every survivor.
The test that killed a mutant last time is remembered (~/.cache/retro/mutant-killers.json, or
$RETRO_MUTANT_KILLERS) and run alone first; only when it no longer kills does the mutant's whole guard
set run, so a rerun of the whole set costs about one test per mutant. Only a test inside the mutant's
guard set is remembered or trusted.
Exit status: 0 when every mutant was killed or is explained, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
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
PYTEST_NOT_RUN = (3, 4, 5)  # internal error, usage error (a missing test path), no tests collected


@dataclass(frozen=True)
class Mutant:
    name: str
    file: str
    old: str  # must occur exactly once in the file
    new: str
    tests: tuple[str, ...]
    explained: str = ""  # why a survivor is acceptable (empty: it must be killed)


VIC_TESTS = ("tests/vic",)
STUB_TESTS = ("tests/vic/test_c64_stubs.py",)
CPU_TESTS = ("tests/cpu",)
BATCH_TESTS = ("tests/cpu/test_batch_vectors.py", "tests/routines/test_batch_check.py")
CHECK_TESTS = ("tests/routines/test_user_specs.py", "tests/routines/test_routines_cli.py",
               "tests/routines/test_routines_exhaustive.py")
TIMELINE_TESTS = ("tests/vic", "tests/cpu/test_machine.py")
NES_TESTS = ("tests/cpu/test_machine.py", "tests/nes")
NES_SCENE_TESTS = ("tests/nes/test_nes_scene_check.py",)
APU_TESTS = ("tests/nes/test_apu_frame.py",)
BUDGET_TESTS = ("tests/vic", "tests/test_machines.py", "tests/test_commands.py")
STABILITY_TESTS = ("tests/study/test_stability_pinned.py", "tests/study/test_stability_report_pinned.py",
                   "tests/study/test_study_cli.py")
FIELD_TESTS = ("tests/test_fields.py",)
COMPILED_TESTS = ("tests/cpu/test_compiled.py",)
COMPILED_VECTOR_TESTS = ("tests/cpu/test_compiled_vectors.py",)  # needs RETRO_CPU_VECTORS
IFCONV_TESTS = ("tests/cpu/test_compiled_ifconvert.py",)
WORKER_TESTS = ("tests/test_workers.py",)
STREAM_TESTS = ("tests/routines/test_case_stream.py",)
GRID_TESTS = ("tests/routines/test_grid_columns.py", "tests/routines/test_case_stream.py")
TABLE_ROW_TESTS = ("tests/routines/test_table_rows.py",)
FLOW_TESTS = ("tests/cpu/test_flow_values.py", "tests/routines/test_static_smc.py")
TALLY_TESTS = ("tests/routines/test_tally_blocks.py",)
COMMAND_TESTS = ("tests/test_commands.py", "tests/test_cli_foundation.py", "tests/routines/test_routines_cli.py")

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
           "self._advance(t if register in _SWITCH_PIXEL else t + 1)", "self._advance(t)", VIC_TESTS),
    Mutant("collision-latch-delay", "retro/chips/vic/constants.py",
           "COLLISION_LATCH_DELAY = 4", "COLLISION_LATCH_DELAY = 3", VIC_TESTS),
    Mutant("d019-ack-ignored", "retro/chips/vic/device.py",
           "self.irq_latch &= ~value & IRQ_SOURCES", "self.irq_latch &= IRQ_SOURCES", VIC_TESTS),
    # ---- the late timing rules (issue 26 part 5: tests/vic/test_timing_rules_late.py) ----------------
    Mutant("d012-write-onto-the-line-ignored", "retro/chips/vic/device.py",
           "if compare != old_compare and compare == self._raster_line(t + 1):", "if False:", VIC_TESTS),
    Mutant("d012-write-match-seen-by-the-writing-instruction", "retro/chips/vic/device.py",
           "self._raster_match_at = t + 1  # the compare's cycle", "self.irq_latch |= IRQ_RASTER  # the compare's cycle",
           VIC_TESTS),
    Mutant("d012-write-latches-without-a-change", "retro/chips/vic/device.py",
           "if compare != old_compare and compare == self._raster_line(t + 1):",
           "if compare == self._raster_line(t + 1):", VIC_TESTS),
    Mutant("d015-acts-at-once", "retro/chips/vic/device.py",
           "self._sampled_registers(self.bad_lines_allowed, self.sprite_enable)",
           "self._sampled_registers(self.bad_lines_allowed, written)", VIC_TESTS),
    Mutant("sprite-shown-without-its-display-check", "retro/chips/vic/device.py",
           "self.sprite_enable & self.sprite_display)", "self.sprite_enable)", VIC_TESTS),
    Mutant("sprite-collides-as-written", "retro/chips/vic/device.py",
           "self.sprite_enable & self.sprite_display)", "written)", VIC_TESTS),
    Mutant("sprite-dma-check-one-cycle", "retro/chips/vic/constants.py",
           "SPRITE_DMA_CHECK_CYCLES = 2", "SPRITE_DMA_CHECK_CYCLES = 1", VIC_TESTS),
    Mutant("sprite-dma-check-a-cycle-early", "retro/chips/vic/device.py",
           "first_check = video.sprite0_fetch_cycle - BA_LEAD - 1",
           "first_check = video.sprite0_fetch_cycle - BA_LEAD - 2", VIC_TESTS),
    Mutant("bad-lines-follow-den-at-once", "retro/chips/vic/device.py",
           "bus_registers = self._sampled_registers(self.bad_lines_allowed, self.sprite_enable)",
           "bus_registers = self._sampled_registers(written_den, self.sprite_enable)", VIC_TESTS),
    Mutant("display-follows-bad-lines-only", "retro/chips/vic/device.py",
           "self._sampled_registers(self.display_opened,",
           "self._sampled_registers(self.bad_lines_allowed,", VIC_TESTS),
    # ---- a sprite X write within a line (tests/vic/test_sprite_x_write.py) ------------------------------
    Mutant("sprite-x-write-moves-a-started-row", "retro/chips/vic/device.py",
           "self._rows_held[n] = (until, old_x)", "self._rows_held.pop(n, None)", VIC_TESTS),
    Mutant("sprite-x-write-passed-x-starts-a-row", "retro/chips/vic/device.py",
           "self._rows_held[n] = (until, None)", "self._rows_held.pop(n, None)", VIC_TESTS),
    Mutant("sprite-x-write-compared-in-its-own-cycle", "retro/chips/vic/device.py",
           "slot = first_new * PIXELS_PER_CYCLE", "slot = (first_new - 1) * PIXELS_PER_CYCLE", VIC_TESTS),
    Mutant("sprite-x-write-held-a-line-longer", "retro/chips/vic/device.py",
           "until = end // PIXELS_PER_CYCLE + 1", "until = end // PIXELS_PER_CYCLE + 1 + video.cycles_per_line",
           VIC_TESTS),
    Mutant("den-in-line-30-only-at-its-start", "retro/chips/vic/device.py",
           "        if line == GRAPHICS_FIRST_LINE:\n", "        if False:\n", VIC_TESTS),
    Mutant("den-in-window-line-only-at-its-start", "retro/chips/vic/device.py",
           "if line == WINDOW_LINES[1 if self.registers[REG_CONTROL1] & CONTROL1_RSEL else 0][0]:",
           "if False:", VIC_TESTS),
    Mutant("yscroll-write-keeps-the-bad-lines", "retro/chips/vic/dma.py",
           "(_BAD_LINE_BITS if r == REG_CONTROL1 else 0xFF)", "(CONTROL1_DEN if r == REG_CONTROL1 else 0xFF)",
           ("tests/vic/test_timing_rules_late.py",)),
    Mutant("vic-bank-not-inverted", "retro/chips/vic/fetch.py",
           "return CIA2_BANK_BITS - (self._pins() & CIA2_BANK_BITS)", "return self._pins() & CIA2_BANK_BITS", ("tests/vic/test_vic_fetch.py",)),
    Mutant("vic-pointers-after-screen-off-by-8", "retro/chips/vic/constants.py",
           "SPRITE_POINTERS = 0x03F8", "SPRITE_POINTERS = 0x03F0", ("tests/vic/test_vic_fetch.py",)),
    Mutant("vic-no-char-rom-window", "retro/chips/vic/constants.py",
           "CHAR_ROM_BANKS = (0, 2)", "CHAR_ROM_BANKS = ()", ("tests/vic/test_vic_fetch.py",)),
    # CIA 1's timers and the ROM stubs of a C64 program run (spritescan's startup measures the line with timer A)
    Mutant("cia-timer-counts-in-its-start-cycle", "retro/chips/cia/timers.py",
           "return (self.counter - elapsed if self.running else self.counter), False, self.running",
           "return (self.counter - elapsed - 1 if self.running else self.counter), False, self.running", STUB_TESTS),
    Mutant("cia-continuous-period-is-the-latch", "retro/chips/cia/timers.py",
           "(elapsed - self.counter - 1) % (self.latch + 1)", "(elapsed - self.counter - 1) % max(self.latch, 1)",
           STUB_TESTS),
    Mutant("cia-high-byte-loads-a-running-timer", "retro/chips/cia/timers.py",
           "            if not self.running:  # \"following", "            if True:  # \"following", STUB_TESTS),
    Mutant("cia-one-shot-keeps-running", "retro/chips/cia/timers.py",
           "        if self.one_shot:\n            return self.latch, True, False",
           "        if False:\n            return self.latch, True, False", STUB_TESTS),
    Mutant("cia-icr-read-keeps-the-flags", "retro/chips/cia/timers.py",
           "            self.flags = 0\n            return value", "            return value", STUB_TESTS),
    Mutant("cia-interrupt-let-through-silently", "retro/chips/cia/timers.py",
           "        self._refuse_interrupt(address, value)", "        pass", STUB_TESTS),
    Mutant("linprt-without-the-sign-space", "retro/machines/c64_stubs.py",
           'for char in f" {mpu.a << 8 | mpu.x}":', 'for char in f"{mpu.a << 8 | mpu.x}":', STUB_TESTS),
    Mutant("strout-runs-past-a-quote", "retro/machines/c64_stubs.py",
           "if petscii in (0, QUOTE):", "if petscii == 0:", STUB_TESTS),
    Mutant("screen-editor-row-pointer-stale", "retro/machines/c64_stubs.py",
           "        memory[PNT], memory[PNT + 1] = line & 0xFF, line >> 8\n", "", STUB_TESTS),
    Mutant("ioinit-leaves-cia-1-running", "retro/machines/c64_stubs.py",
           "            self.cia1.write(CIA1_BASE + register, CR_AFTER_IOINIT, cycle)", "            pass", STUB_TESTS),
    Mutant("vic-memory-read-nowhere", "retro/chips/vic/device.py",
           "if self.fetcher is not None and self.fetcher.due(self.video, self.registers, lo, until):",
           "if False:", ("tests/vic/test_vic_fetch.py",)),
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
    Mutant("cycle-mismatches-not-counted", "retro/analysis/check/tally.py",
           "    out.cycle_mismatches = len(cycle_wrong)\n", "    out.cycle_mismatches = 0\n", CHECK_TESTS),
    Mutant("static-bound-violations-ignored", "retro/analysis/check/verdicts.py",
           "if t.cpu_max > static.worst:", "if False:", CHECK_TESTS),
    Mutant("static-min-violations-ignored", "retro/analysis/check/verdicts.py",
           "if t.cpu_min < static.best:", "if False:", CHECK_TESTS),
    Mutant("budget-not-checked", "retro/analysis/check/verdicts.py",
           "if t.cycles_count and t.cycles_max > routine.budget:", "if False:", CHECK_TESTS),
    Mutant("static-budget-not-checked", "retro/analysis/check/verdicts.py",
           "if static is not None and static.worst > routine.budget:", "if False:", CHECK_TESTS),
    Mutant("outside-domain-counted-as-inside", "retro/analysis/check/tally.py",
           "        inside &= held\n", "        pass\n", CHECK_TESTS),
    Mutant("result-mismatch-not-counted", "retro/analysis/check/tally.py",
           "out.result_mismatches = len(wrong_inside)", "out.result_mismatches = 0", CHECK_TESTS),
    Mutant("run-error-not-stopping", "retro/analysis/check/engines.py",
           "            stop, message = \"run\", str(exc)\n            break",
           "            stop, message = \"run\", str(exc)\n            continue", CHECK_TESTS),
    Mutant("stalls-counted-as-cpu-cycles", "retro/analysis/check/tally.py",
           "cpu = block.cycles[:n] - block.stolen[:n]", "cpu = block.cycles[:n]", CHECK_TESTS),
    Mutant("cpu-extremes-taken-from-stalled-cycles", "retro/analysis/check/tally.py",
           "    if not stalled:  # (no scene): the CPU's cycles are the cycles", "    if True:", CHECK_TESTS
           + ("tests/routines/test_scene_batch.py",)),
    Mutant("outside-examples-never-kept", "retro/analysis/check/tally.py",
           "    if outside_wanted > 0 and out.outside_wrong:", "    if False:", ("tests/test_check_golden.py",)),
    Mutant("tally-first-extreme-taken-outside-the-domain", "retro/analysis/check/tally.py",
           "    if calls.everywhere or calls.inside[first]:", "    if True:", TALLY_TESTS),
    Mutant("tally-block-inside-judged-by-its-first-case", "retro/analysis/check/tally.py",
           "everywhere=bool(inside.all())", "everywhere=bool(inside[:1].all())", TALLY_TESTS),
    Mutant("tally-block-right-judged-by-its-first-case", "retro/analysis/check/tally.py",
           "all_equal=bool(equal.all())", "all_equal=bool(equal[:1].all())", TALLY_TESTS),
    Mutant("tally-wrong-outside-counted-as-mismatch", "retro/analysis/check/tally.py",
           "np.flatnonzero(~calls.equal if calls.everywhere else calls.inside & ~calls.equal)",
           "np.flatnonzero(~calls.equal)", TALLY_TESTS),
    Mutant("tally-cycles-sum-counts-the-cases-outside", "retro/analysis/check/tally.py",
           "int(cycles.sum() - cycles[~calls.inside].sum())", "int(cycles.sum())", TALLY_TESTS),
    # ---- routine specs and static analysis -------------------------------------------------------
    Mutant("jsr-callee-cost-dropped", "retro/cpu/flow.py",
           "return _Effect((cycles + callee.best, cycles + callee.worst), after=_returned(callee.exit))",
           "return _Effect((cycles, cycles), after=_returned(callee.exit))",
           CHECK_TESTS),
    Mutant("page-crossing-always-possible", "retro/cpu/value_steps.py",
           "return int(lowest(low_bytes) + lowest(index) > 0xFF), int(highest(low_bytes) + highest(index) > 0xFF)",
           "return int(lowest(low_bytes) + lowest(index) > 0xFF), 1", FLOW_TESTS),
    Mutant("page-crossing-never-certain", "retro/cpu/value_steps.py",
           "return int(lowest(low_bytes) + lowest(index) > 0xFF), int(highest(low_bytes) + highest(index) > 0xFF)",
           "return 0, int(highest(low_bytes) + highest(index) > 0xFF)", FLOW_TESTS),
    Mutant("known-branch-counted-both-ways", "retro/cpu/value_steps.py",
           "return Step(narrowed(state, flag, other) if value & other else None,",
           "return Step(narrowed(state, flag, other),", FLOW_TESTS),
    Mutant("self-modified-operand-read-as-loaded", "retro/cpu/value_steps.py",
           "    b1 = state.read(memory, pc + 1)\n    if mode == \"zpg\":",
           "    b1 = memory.initial(pc + 1)\n    if mode == \"zpg\":", FLOW_TESTS),
    Mutant("compare-n-window-off-by-one", "retro/cpu/value_steps.py",
           "if (doubled >> ((r + 129) & 0xFF)) & HALF_RANGE:", "if (doubled >> ((r + 128) & 0xFF)) & HALF_RANGE:",
           FLOW_TESTS),
    Mutant("compare-n-over-the-combination-cap", "retro/cpu/value_steps.py",
           "n = EITHER if register.bit_count() * operand.bit_count() > MAX_COMBINATIONS else",
           "n = EITHER if False else", FLOW_TESTS + ("tests/test_check_golden.py",)),
    Mutant("auto-compiled-from-a-cycle-more", "retro/analysis/check/engines.py",
           "return cycles >= AUTO_COMPILED_CYCLES", "return cycles > AUTO_COMPILED_CYCLES",
           ("tests/routines/test_compiled_check.py",)),
    Mutant("auto-expects-the-mean-of-the-bounds", "retro/analysis/check/engines.py",
           "return (max(best, 1) * max(worst, 1)) ** 0.5", "return (best + worst) / 2",
           ("tests/routines/test_compiled_check.py",)),
    Mutant("auto-ignores-the-work", "retro/analysis/check/engines.py",
           "        if not compiled_pays(cycles):", "        if not compiled_pays(calls * 1000):",
           ("tests/routines/test_compiled_check.py",)),
    Mutant("assembled-cache-ignores-edited-includes", "retro/assembler.py",
           "_file_sum(pair[0]) == pair[1] for pair in read", "True for pair in read", ("tests/test_assembler.py",)),
    Mutant("assembled-cache-hides-the-includes", "retro/assembler.py",
           "    for name, _ in read:\n        note_input(name, \"included file\")\n    return program",
           "    return program", ("tests/test_assembler.py",)),
    Mutant("analysis-reads-memory-after-the-cases", "retro/analysis/check/verdicts.py",
           "memory = bytes(runner.call_image)", "memory = bytes(runner.machine.memory)", FLOW_TESTS),
    Mutant("flag-input-ignored", "retro/routines/input_plan.py",
           "p |= (values[index] != 0) * bit", "p |= 0 * bit",
           ("tests/routines",)),
    Mutant("high-byte-of-output-dropped", "retro/routines/outputs.py",
           "value = value | widen(byte) << (8 * shift)", "value = value | (widen(byte) if shift == 0 else widen(0))",
           ("tests/routines",)),
    # ---- mul16 (asm/mul16.s, its sweep) -------------------------------------------------------------
    Mutant("mul16-add-without-clc", "asm/mul16.s", "        clc\n        lda p2\n", "        lda p2\n",
           ("tests/routines/test_routines_exhaustive.py",)),
    Mutant("mul16-sweep-misses-the-last-a", "retro/routines/builtin_cases.py",
           'return Grid({"a": WORD, "b": WORD})', 'return Grid({"a": WORD - 1, "b": WORD})',
           ("tests/routines/test_routines_exhaustive.py",)),
    # ---- the batched core and its checks --------------------------------------------------------
    Mutant("batch-branch-page-costs-nothing", "retro/cpu/batch_handlers.py",
           "extra_taken + crossed * BRANCH_PAGE_CYCLES, pc, cycles)", "extra_taken, pc, cycles)",
           BATCH_TESTS),
    Mutant("batch-page-cross-costs-nothing", "retro/cpu/batch_handlers.py",
           "if penalised and crossed is not False:", "if False:", BATCH_TESTS),
    Mutant("batch-decimal-high-adjust-off-by-one", "retro/cpu/batch_handlers.py",
           "high = np.where(high >= 0xA0, high + 0x60, high)", "high = np.where(high >= 0xA1, high + 0x60, high)",
           BATCH_TESTS),
    Mutant("batch-rts-without-plus-one", "retro/cpu/batch_handlers.py",
           "return _uniform(((g.pull() << 8 | low) + 1) & WORD)", "return _uniform((g.pull() << 8 | low) & WORD)",
           BATCH_TESTS),
    Mutant("batch-lane-rows-ignored-on-read", "retro/cpu/lane_memory.py",
           "            row = self.rows.get(int(address))\n            if row is None:",
           "            row = None\n            if row is None:", BATCH_TESTS),
    Mutant("batch-result-mismatches-not-counted", "retro/analysis/check/tally.py",
           "out.result_mismatches = len(wrong_inside)", "out.result_mismatches = 0", BATCH_TESTS),
    Mutant("engine-call-disagreement-ignored", "retro/analysis/check/engines.py",
           "    if batch.row(i) == answer and int(batch.cycles[i]) == cycles:", "    if True:", BATCH_TESTS),
    Mutant("engine-disagreement-not-counted", "retro/analysis/check/results.py",
           "found += self.agreement.engine_mismatches + self.agreement.cycle_mismatches", "found += 0",
           BATCH_TESTS),
    Mutant("held-entry-reruns-dropped", "retro/analysis/check/run.py",
           "        totals.merge(held_entry_tally(sweep.spec, sweep.seed, sweep.start, held, sweep.rerun_engine))",
           "        pass",
           ("tests/routines/test_entry_state.py",)),
    Mutant("held-entry-reruns-given-the-first-blocks-places", "retro/analysis/check/entry_runs.py",
           "np.concatenate([b.positions + b.first for b in baselines])",
           "np.concatenate([b.positions + baselines[0].first for b in baselines])",
           ("tests/routines/test_entry_state.py",)),
    Mutant("compiled-reruns-without-the-varied-flags", "retro/routines/batch_runs.py",
           "[bits & bit for bit in bit_list]", "[bits & 0 for bit in bit_list]",
           ("tests/routines/test_entry_state.py",)),
    Mutant("compiled-reruns-not-cross-checked", "retro/analysis/check/entry_runs.py",
           "    if differ.any():", "    if False:", ("tests/routines/test_entry_state.py",)),
    Mutant("compiled-reruns-cross-checked-per-task-not-per-block", "retro/analysis/check/entry_runs.py",
           "CROSS_CHECKED * max(1, len(baselines) // CROSS_CHECKED_BLOCKS)", "CROSS_CHECKED",
           ("tests/routines/test_entry_state.py",)),
    Mutant("long-sweep-tasks-not-larger", "retro/analysis/check/run.py",
           "long = LONG_SWEEP_FACTOR if planned >= LONG_SWEEP_CALLS else 1", "long = 1",
           ("tests/routines/test_entry_state.py",)),
    Mutant("agreement-run-skipped", "retro/analysis/check/run.py",
           "agreement.merge(agreement_chunk(spec, seed, columns, engine, start))", "pass", BATCH_TESTS),
    # the timing model the recording loop sums as it runs (retro.cpu.mpu.run_recorded): the engine agreement's
    Mutant("recorded-model-skips-penalties", "retro/cpu/mpu.py",
           "modelled += bases[op] if rule is None else bases[op] + rule(read, pc, self.x, self.y, self.p, None)",
           "modelled += bases[op]", BATCH_TESTS + ("tests/cpu/test_machine.py",)),
    Mutant("recorded-model-without-the-pointer", "retro/cpu/mpu.py",
           "rule(read, pc, self.x, self.y, self.p, None)", "rule(read, pc, self.x, self.y, self.p, 0)",
           BATCH_TESTS + ("tests/cpu/test_machine.py",)),
    Mutant("recorded-model-swaps-x-and-y", "retro/cpu/mpu.py",
           "rule(read, pc, self.x, self.y, self.p, None)", "rule(read, pc, self.y, self.x, self.p, None)",
           BATCH_TESTS + ("tests/cpu/test_machine.py",)),
    Mutant("fused-bne-taken-on-zero", "retro/cpu/mpu.py",
           "(0xD0, FLAG_Z, False)", "(0xD0, FLAG_Z, True)", CPU_TESTS),
    Mutant("fused-compare-without-carry", "retro/cpu/mpu.py",
           "                | (FLAG_C if diff >= 0 else 0)\n            self.pc = pc + 1",
           "                | 0\n            self.pc = pc + 1", CPU_TESTS),
    Mutant("fused-lsr-a-carry-from-the-top-bit", "retro/cpu/mpu.py",
           "(a & FLAG_C) | (0 if value else FLAG_Z)", "(a >> 7) | (0 if value else FLAG_Z)", CPU_TESTS),
    Mutant("fused-dec-zpg-increments", "retro/cpu/mpu.py", "0xC6: step_zpg(-1)", "0xC6: step_zpg(1)", CPU_TESTS),
    Mutant("fused-sbc-aby-indexed-by-x", "retro/cpu/mpu.py",
           "self._sbc(self.ByteAt(self._indexed(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8, self.y)))",
           "self._sbc(self.ByteAt(self._indexed(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8, self.x)))",
           CPU_TESTS),
    Mutant("fused-cpx-immediate-read-as-zero-page", "retro/cpu/mpu.py",
           '0xE0: compare("x", False)', '0xE0: compare("x", True)', CPU_TESTS),
    Mutant("fused-lda-indexed-by-the-other-register", "retro/cpu/mpu.py",
           "self.x if by_x else self.y", "self.y if by_x else self.x", CPU_TESTS),
    Mutant("recorded-run-ram-only-with-devices", "retro/cpu/mpu.py",
           "ram_only = devices.count(None) == len(devices)", "ram_only = True", ("tests/cpu/test_machine.py",)),
    Mutant("recorded-run-keeps-ram-accessors", "retro/cpu/mpu.py",
           "            if ram_only:\n                del self.ByteAt, self.WriteByte\n", "",
           ("tests/cpu/test_machine.py",)),
    Mutant("machine-table-inputs-shifted", "retro/routines/runner.py",
           "writes.extend(zip(addresses, value))", "writes.extend(zip(addresses[1:], value))",
           ("tests/routines/test_batch_check.py", "tests/test_check_golden.py")),
    # ---- the parallel work (retro/workers.py) and a task's cases (retro/routines/cases.py) ------------
    Mutant("results-merged-in-finishing-order", "retro/workers.py",
           "if report(pending.popleft().result()):", "if report(pending.pop().result()):", WORKER_TESTS),
    Mutant("workers-take-ctrl-c", "retro/workers.py",
           "signal.signal(signal.SIGINT, signal.SIG_IGN)", "pass", WORKER_TESTS),
    Mutant("small-check-starts-a-cluster", "retro/analysis/check/run.py",
           "needed = plan.unknown or plan.known >= PARALLEL_CALLS[sweep.engine]", "needed = True", WORKER_TESTS),
    Mutant("stream-cuts-a-block-one-late", "retro/routines/cases.py",
           "yield block if seen >= skip else [column[skip - seen:] for column in block]",
           "yield block if seen >= skip else [column[skip - seen + 1:] for column in block]", STREAM_TESTS),
    Mutant("stream-seeks-from-the-first-block", "retro/routines/cases.py",
           "    first = start // SEEK_BLOCK\n", "    first = 0\n", STREAM_TESTS),
    Mutant("one-generator-for-every-block", "retro/routines/cases.py",
           "return rng if block == 0 else np.random.Generator(rng.bit_generator.jumped(block))", "return rng",
           STREAM_TESTS),
    Mutant("sweep-function-count-skips-one-case-too-many", "retro/routines/cases.py",
           "if produced + n <= skip:  # wholly before the first case wanted", "if produced + n <= skip + 1:",
           STREAM_TESTS),
    Mutant("stream-reaches-any-case", "retro/routines/cases.py",
           "return first == done or (part.seek is not None and not part.from_start)", "return True", STREAM_TESTS),
    Mutant("grid-sweep-made-from-its-start", "retro/routines/cases.py",
           "        lo = start\n        start = 0\n", "        lo = 0\n        start = 0\n", STREAM_TESTS),
    Mutant("grid-first-axis-fastest", "retro/routines/grid.py",
           "for index in reversed(range(len(self.axis_columns))):", "for index in range(len(self.axis_columns)):", GRID_TESTS),
    Mutant("grid-first-run-cut-at-the-end", "retro/routines/grid.py",
           "runs[0] = min((first + 1) * stride, hi) - lo", "runs[0] = min(stride, n)", GRID_TESTS),
    Mutant("grid-period-from-its-start", "retro/routines/grid.py",
           "self._periodic(index, k, stride, lo % period, n)", "self._periodic(index, k, stride, 0, n)",
           GRID_TESTS),
    Mutant("grid-kept-period-without-its-phase", "retro/routines/grid.py",
           "return _Column(kept.array[phase:phase + n], kept.extremes)", "return _Column(kept.array[:n], kept.extremes)",
           GRID_TESTS),
    Mutant("grid-laid-out-period-kept-whatever-the-block-length", "retro/routines/grid.py",
           "        key = (index, column, n)\n", "        key = (index, column)\n", GRID_TESTS),
    Mutant("grid-laid-out-period-one-combination-short", "retro/routines/grid.py",
           "array = np.empty(len(period) + n - 1, dtype=np.int64)", "array = np.empty(len(period) + n - 2, dtype=np.int64)",
           GRID_TESTS),
    Mutant("grid-make-writes-the-shared-columns", "retro/routines/grid.py",
           "view = _read_only(axis.array)", "view = axis.array", GRID_TESTS),
    Mutant("grid-known-column-negative-passes", "retro/routines/cases.py",
           "if extremes[0] < 0 or extremes[1] >= limit:", "if extremes[1] >= limit:", GRID_TESTS),
    Mutant("circle-random-tight-at-255-kept-apart", "retro/routines/builtin_cases.py",
           "fits = radius_sum <= 255", "fits = radius_sum < 255", GRID_TESTS),
    Mutant("circle-random-draws-out-of-case-order", "retro/routines/builtin_cases.py",
           "rng.integers(0, 2, size=len(tight))", "rng.integers(0, 2, size=len(tight))[::-1]", GRID_TESTS),
    Mutant("stream-grid-cut-from-the-part-s-start", "retro/routines/cases.py",
           "yield from part.aligned(skip, -done % size, size)", "yield from part.aligned(skip, 0, size)", GRID_TESTS),
    Mutant("product-draws-inputs-in-reverse", "retro/routines/cases.py",
           "            for i, port in enumerate(ports):\n                if columns[i] is None:\n                    out[i]",
           "            for i, port in reversed(list(enumerate(ports))):\n                if columns[i] is None:\n                    out[i]",
           GRID_TESTS),
    Mutant("product-grid-first-input-fastest", "retro/routines/cases.py",
           "np.arange(ports[i].count, dtype=np.uint64)) for i in swept})",
           "np.arange(ports[i].count, dtype=np.uint64)) for i in reversed(swept)})", GRID_TESTS),
    Mutant("grid-constant-kept-whatever-its-length", "retro/routines/grid.py",
           "    key = (value, n)\n", "    key = (value, 0)\n", GRID_TESTS),
    Mutant("column-fits-without-negatives", "retro/routines/cases.py",
           "column.view(np.uint64).max() < limit", "column.max() < limit", GRID_TESTS),
    Mutant("stop-leaves-the-cluster-open", "retro/workers.py",
           "            cluster.close(timeout=STOP_CLOSE_SECONDS)\n", "            pass\n",
           ("tests/test_workers.py::test_ctrl_c_cancels_the_sweep_and_leaves_no_worker",)),
    Mutant("numba-not-ready-in-the-forkserver", "retro/workers.py",
           'PRELOAD_IF_IMPORTED = {"numba.np.arraymath": ("numba", "retro.cpu.numba_ready")}',
           'PRELOAD_IF_IMPORTED = {"numba.np.arraymath": ("numba",)}',
           WORKER_TESTS),
    # ---- the CPU's timeline on a C64: sprite DMA, Bad Lines, BA (retro/chips/vic) ------------------
    Mutant("sprite-dma-retriggers-while-on", "retro/chips/vic/model.py",
           "if (line % video.lines) & Y_COMPARE_MASK == y and line >= free_from:",
           "if (line % video.lines) & Y_COMPARE_MASK == y:", TIMELINE_TESTS),
    Mutant("sprite0-fetch-cycle-6569-59", "retro/chips/vic/constants.py",
           "sprite0_fetch_cycle=58, display_check_cycle=58)", "sprite0_fetch_cycle=59, display_check_cycle=58)",
           TIMELINE_TESTS),
    Mutant("sprite0-fetch-cycle-6567r8-60", "retro/chips/vic/constants.py",
           "sprite0_fetch_cycle=59, display_check_cycle=59, repeated_x_cycle=63)",
           "sprite0_fetch_cycle=60, display_check_cycle=59, repeated_x_cycle=63)", TIMELINE_TESTS),
    Mutant("sprite0-fetch-cycle-6567r56a-60", "retro/chips/vic/constants.py",
           "sprite0_fetch_cycle=59, display_check_cycle=59)", "sprite0_fetch_cycle=60, display_check_cycle=59)",
           TIMELINE_TESTS),
    Mutant("ba-lead-2", "retro/chips/vic/constants.py", "BA_LEAD = 3", "BA_LEAD = 2", TIMELINE_TESTS),
    Mutant("sprite-dma-one-cycle", "retro/chips/vic/dma.py",
           "for offset in range(-BA_LEAD, SPRITE_DMA_CYCLES):", "for offset in range(-BA_LEAD, 1):", TIMELINE_TESTS),
    Mutant("sprite-dma-ignores-y-expansion", "retro/chips/vic/dma.py",
           "registers[REG_SPRITE_Y0 + 2 * n], bool(expanded >> n & 1))",
           "registers[REG_SPRITE_Y0 + 2 * n], False)", TIMELINE_TESTS),
    Mutant("bad-line-yscroll-off-by-one", "retro/chips/vic/dma.py",
           "and (line & CONTROL1_YSCROLL) == (control1 & CONTROL1_YSCROLL))",
           "and ((line + 1) & CONTROL1_YSCROLL) == (control1 & CONTROL1_YSCROLL))", TIMELINE_TESTS),
    Mutant("bad-line-without-den", "retro/chips/vic/dma.py",
           "    control1 = registers[REG_CONTROL1]\n", "    control1 = registers[REG_CONTROL1] | CONTROL1_DEN\n",
           TIMELINE_TESTS),
    Mutant("bad-line-range-without-f7", "retro/chips/vic/dma.py",
           "GRAPHICS_FIRST_LINE <= line <= BAD_LINE_LAST", "GRAPHICS_FIRST_LINE <= line < BAD_LINE_LAST",
           TIMELINE_TESTS),
    Mutant("bad-line-range-without-30", "retro/chips/vic/dma.py",
           "GRAPHICS_FIRST_LINE <= line <= BAD_LINE_LAST", "GRAPHICS_FIRST_LINE < line <= BAD_LINE_LAST",
           TIMELINE_TESTS),
    Mutant("bad-line-stolen-from-14", "retro/chips/vic/constants.py",
           "BAD_LINE_FIRST_STOLEN = 15", "BAD_LINE_FIRST_STOLEN = 14", TIMELINE_TESTS),
    Mutant("bad-line-cache-key-without-den", "retro/chips/vic/dma.py",
           "_BAD_LINE_BITS = CONTROL1_DEN | CONTROL1_YSCROLL", "_BAD_LINE_BITS = CONTROL1_YSCROLL", TIMELINE_TESTS),
    Mutant("d011-write-keeps-the-old-ba", "retro/chips/vic/device.py",
           "        self._bus = bus_schedule(self.video, bus_registers)", "        pass", TIMELINE_TESTS),
    Mutant("sprite-dma-write-keeps-the-old-ba", "retro/chips/vic/device.py",
           "                self._bus = bus_schedule(self.video, self.registers)", "                pass", TIMELINE_TESTS),
    Mutant("ba-known-high-kept-after-an-access", "retro/cpu/mpu.py",
           "        self.ba_high_until = -1  # the access may change when the bus is taken", "        pass",
           TIMELINE_TESTS),
    Mutant("cpu-stops-on-writes-too", "retro/cpu/mpu.py",
           "            if not writes >> i & 1:", "            if True:", TIMELINE_TESTS),
    Mutant("rmw-writes-only-last-cycle", "retro/cpu/mpu.py",
           "from_end = (1, 2) if op in self.RMW_OPCODES", "from_end = (1,) if op in self.RMW_OPCODES", TIMELINE_TESTS),
    Mutant("interrupt-pushes-stop-on-ba", "retro/cpu/mpu.py",
           "INTERRUPT_WRITES = (3, 4, 5)", "INTERRUPT_WRITES = ()", TIMELINE_TESTS),
    # ---- interrupts: the 6502's latency and I flag, the VIC-II's IRQ output, the NES NMI ------------
    Mutant("interrupt-sequence-6-cycles", "retro/cpu/mpu.py",
           "INTERRUPT_CYCLES = 7", "INTERRUPT_CYCLES = 6", TIMELINE_TESTS),
    Mutant("poll-in-last-cycle", "retro/cpu/mpu.py",
           "if op in BRANCH_OPCODES and self.excycles == 1 else end - 2",
           "if op in BRANCH_OPCODES and self.excycles == 1 else end - 1", TIMELINE_TESTS),
    Mutant("taken-branch-polls-as-usual", "retro/cpu/mpu.py",
           "poll = end - 3 if op in BRANCH_OPCODES and self.excycles == 1 else end - 2", "poll = end - 2",
           TIMELINE_TESTS),
    Mutant("page-crossing-branch-polls-early-too", "retro/cpu/mpu.py",
           "if op in BRANCH_OPCODES and self.excycles == 1 else", "if op in BRANCH_OPCODES and self.excycles >= 1 else",
           TIMELINE_TESTS),
    Mutant("cli-sei-plp-act-before-the-poll", "retro/cpu/mpu.py",
           "masked = (i_before if op in I_CHANGED_AFTER_POLL else self.p & FLAG_I)", "masked = self.p & FLAG_I",
           TIMELINE_TESTS),
    Mutant("plp-acts-before-the-poll", "retro/cpu/mpu.py",
           "I_CHANGED_AFTER_POLL = frozenset({OPCODE_CLI, OPCODE_SEI, OPCODE_PLP})",
           "I_CHANGED_AFTER_POLL = frozenset({OPCODE_CLI, OPCODE_SEI})", TIMELINE_TESTS),
    Mutant("rti-acts-after-the-poll", "retro/cpu/mpu.py",
           "I_CHANGED_AFTER_POLL = frozenset({OPCODE_CLI, OPCODE_SEI, OPCODE_PLP})",
           "I_CHANGED_AFTER_POLL = frozenset({OPCODE_CLI, OPCODE_SEI, OPCODE_PLP, 0x40})", TIMELINE_TESTS),
    Mutant("interrupt-leaves-i-clear", "retro/cpu/mpu.py", "self.p = (self.p | FLAG_I) & ~self.interrupt_clears",
           "self.p = self.p & ~self.interrupt_clears",
           TIMELINE_TESTS),
    Mutant("interrupt-pushes-b-set", "retro/cpu/mpu.py",
           "self.stPush((self.p | FLAG_U) & ~FLAG_B)", "self.stPush(self.p | FLAG_U | FLAG_B)", TIMELINE_TESTS),
    Mutant("nmi-through-the-irq-vector", "retro/cpu/mpu.py",
           "vector = NMI_VECTOR if kind == \"NMI\" else IRQ_VECTOR", "vector = IRQ_VECTOR", NES_TESTS),
    Mutant("nmi-masked-by-i", "retro/cpu/mpu.py",
           "if poll >= lines.nmi_next and lines.nmi_edge(poll):\n            self.pending_interrupt = \"NMI\"",
           "if not masked and poll >= lines.nmi_next and lines.nmi_edge(poll):\n            self.pending_interrupt = \"NMI\"",
           NES_TESTS),
    Mutant("vic-irq-ignores-d01a", "retro/chips/vic/device.py",
           "return bool(self.irq_latch & self.registers[REG_IRQ_ENABLE] & IRQ_SOURCES)",
           "return bool(self.irq_latch & IRQ_SOURCES)", TIMELINE_TESTS),
    Mutant("d019-bit7-ignores-d01a", "retro/chips/vic/model.py",
           "return value | (IRQ_ANY if latched & enabled & IRQ_SOURCES else 0)",
           "return value | (IRQ_ANY if latched & IRQ_SOURCES else 0)", TIMELINE_TESTS),
    Mutant("vic-irq-next-a-cycle-late", "retro/chips/vic/device.py",
           "candidates.append(after + (raster - after) % frame_cycles)",
           "candidates.append(after + (raster - after) % frame_cycles + 1)", TIMELINE_TESTS),
    Mutant("raster-compare-without-bit-8", "retro/chips/vic/model.py",
           "return (registers[REG_CONTROL1] & CONTROL1_RST8) << 1 | registers[REG_RASTER]",
           "return registers[REG_RASTER]", TIMELINE_TESTS),
    Mutant("raster-compare-a-line-late", "retro/chips/vic/model.py",
           "return line * video.cycles_per_line + (RASTER_IRQ_LINE0_DELAY if line == 0 else 0)",
           "return (line + 1) % video.lines * video.cycles_per_line + (RASTER_IRQ_LINE0_DELAY if line == 0 else 0)",
           TIMELINE_TESTS),
    Mutant("nes-no-nmi-at-vblank", "retro/chips/ppu/device.py",
           "        if self.ctrl & CTRL_NMI:\n            self._nmi_output_low(dot)",
           "        if False:\n            self._nmi_output_low(dot)", NES_TESTS),
    Mutant("nes-nmi-enabled-in-vblank-ignored", "retro/chips/ppu/device.py",
           "if self.vblank and value & CTRL_NMI and not enabled:", "if False:", NES_TESTS),
    Mutant("nes-nmi-edge-seen-by-the-writes-own-poll", "retro/chips/ppu/device.py",
           "self.nmi_next = self.nmi_edge_cycle  #", "self.nmi_next = -NEVER  #", NES_TESTS,
           explained="equivalent since nmi_edge also refuses an edge whose cycle is after the poll: moving the "
                     "lower bound earlier changes no poll's outcome; removing both undoes the rule and "
                     "test_the_immediate_nmi_comes_after_the_next_instruction fails (checked by hand)"),
    Mutant("vic-open-border-without-bad-lines-is-border", "retro/chips/vic/device.py",
           "self._sampled_registers(self.display_opened, self.sprite_enable & self.sprite_display)",
           "self._sampled_registers(self.display_opened and self.bad_lines_allowed, self.sprite_enable & self.sprite_display)",
           ("tests/vic/test_timing_rules_late.py",)),
    Mutant("vic-frame-without-bad-lines-shows-the-characters", "retro/chips/vic/graphics.py",
           "displayed = (offset >= 0) & (row < TEXT_ROWS) & bad_lines", "displayed = (offset >= 0) & (row < TEXT_ROWS)",
           ("tests/vic/test_timing_rules_late.py",)),
    Mutant("vic-d01d-write-places-the-row-again", "retro/chips/vic/device.py",
           "            self._switch_rows_in_progress(register, value & 0xFF, t)", "            pass",
           ("tests/vic/test_sprite_shape_write.py",)),
    Mutant("vic-expand-switch-a-pixel-late", "retro/chips/vic/constants.py",
           "EXPAND_X_SWITCH_PIXEL = 6", "EXPAND_X_SWITCH_PIXEL = 7", ("tests/vic/test_sprite_shape_write.py",)),
    Mutant("vic-multicolour-switch-a-pixel-early", "retro/chips/vic/constants.py",
           "MULTICOLOR_SWITCH_PIXEL = 7", "MULTICOLOR_SWITCH_PIXEL = 6", ("tests/vic/test_sprite_shape_write.py",)),
    Mutant("vic-multicolour-switch-keeps-the-pair-flop", "retro/chips/vic/sprite_bits.py",
           "                pair_flop = False", "                pass", ("tests/vic/test_sprite_shape_write.py",)),
    Mutant("vic-switch-from-the-cycle-after-the-write", "retro/chips/vic/device.py",
           "self._advance(t if register in _SWITCH_PIXEL else t + 1)", "self._advance(t + 1)",
           ("tests/vic/test_sprite_shape_write.py",)),
    Mutant("vic-ended-row-takes-the-new-expansion", "retro/chips/vic/device.py",
           "            self._shapes_held[n] = (end // PIXELS_PER_CYCLE + 1, base_expand, base_multicolor, switches)",
           "            if switches:\n                self._shapes_held[n] = (end // PIXELS_PER_CYCLE + 1, base_expand, base_multicolor, switches)",
           ("tests/vic/test_sprite_shape_write.py",)),
    # ---- the APU frame counter's interrupt (retro/chips/apu_frame.py) and OAM DMA after the poll -----
    Mutant("apu-flag-a-cycle-early", "retro/chips/apu_frame.py",
           "FLAG_AFTER_RESTART = 29828", "FLAG_AFTER_RESTART = 29827", APU_TESTS),
    Mutant("apu-no-jitter", "retro/chips/apu_frame.py",
           "ODD_WRITE_DELAY = 1 ", "ODD_WRITE_DELAY = 0 ", APU_TESTS),
    Mutant("apu-other-phase", "retro/chips/apu_frame.py",
           "APU_CYCLE_PARITY = 1", "APU_CYCLE_PARITY = 0", APU_TESTS),
    Mutant("apu-flag-set-once", "retro/chips/apu_frame.py",
           "FLAG_SET_CYCLES = 3", "FLAG_SET_CYCLES = 1", APU_TESTS),
    Mutant("apu-period-29829", "retro/chips/apu_frame.py",
           "FOUR_STEP_PERIOD = 29830", "FOUR_STEP_PERIOD = 29829", APU_TESTS),
    Mutant("apu-irq-line-a-cycle-late", "retro/chips/apu_frame.py",
           "IRQ_LINE_DELAY = 0 ", "IRQ_LINE_DELAY = 1 ", APU_TESTS),
    Mutant("apu-power-on-write-at-the-first-instruction", "retro/chips/apu_frame.py",
           "POWER_ON_WRITE_LEAD = 10 ", "POWER_ON_WRITE_LEAD = 0 ", APU_TESTS),
    Mutant("apu-read-clears-a-flag-set-in-its-cycle", "retro/chips/apu_frame.py",
           "self.cleared_at = cycle - 1 if self._next_flag(cycle) == cycle else cycle", "self.cleared_at = cycle",
           APU_TESTS),
    Mutant("apu-restart-at-the-write", "retro/chips/apu_frame.py",
           "self.previous = _Sequence(self.current.first_flag, restart)", "self.previous = _Sequence(None)",
           APU_TESTS),
    Mutant("apu-five-step-sets-the-flag", "retro/chips/apu_frame.py",
           "first = None if value & MODE_FIVE_STEP else", "first = None if False else", APU_TESTS),
    Mutant("dma-before-the-poll", "retro/cpu/mpu.py",
           "            poll -= self.halted  #", "            pass  #", APU_TESTS),
    # ---- NES scenes in check/cycles/run/profile (retro/machines/nes.py, retro/routines/chip_access.py) --
    Mutant("nes-dma-parity-of-the-machine-clock", "retro/chips/ppu/device.py",
           "(OAM_DMA_ODD_EXTRA if (cycle - self.origin) % 2 else 0)", "(OAM_DMA_ODD_EXTRA if cycle % 2 else 0)",
           NES_SCENE_TESTS),
    Mutant("nes-nmi-entry-without-the-sequence", "retro/machines/nes.py",
           "handler.cycle - (INTERRUPT_CYCLES if sequence_counted else 0)", "handler.cycle", NES_SCENE_TESTS),
    Mutant("nes-batch-ignores-the-nmi", "retro/routines/chip_access.py",
           "if to_nmi is not None and limit >= to_nmi:", "if False:", NES_SCENE_TESTS),
    Mutant("nes-entry-frame-not-drawn", "retro/machines/nes.py",
           "    ppu.advance(ppu.dot_of(machine.cycle))\n    ppu.nmi_pending = False",
           "    ppu.nmi_pending = False", NES_SCENE_TESTS),
    Mutant("nes-budget-from-the-frame-start", "retro/machines/nes.py",
           "(rendering - begins) * ratio.denominator // ratio.numerator, in_nmi)",
           "rendering * ratio.denominator // ratio.numerator, in_nmi)", NES_SCENE_TESTS),
    Mutant("nes-calls-not-restarted", "retro/routines/chip_access.py",
           "        self.ppu.restore(self._snapshot, self.machine.cycle - self.entry.cycle)", "        pass",
           NES_SCENE_TESTS),
    # ---- the raster budget (retro/machines/c64.py) -------------------------------------------------
    Mutant("budget-end-a-cycle-late", "retro/machines/c64.py",
           "position(video, device.time(start + cycles - 1))", "position(video, device.time(start + cycles))",
           BUDGET_TESTS),
    Mutant("budget-frames-not-counted", "retro/machines/c64.py",
           "frames=last_frame - first_frame)", "frames=0)", BUDGET_TESTS),
    Mutant("interrupt-budget-from-the-handler", "retro/machines/c64.py",
           "            opened.append((at, stolen))", "            opened.append((at + entry.cycles, stolen))",
           BUDGET_TESTS),
    Mutant("interrupt-budget-stolen-from-the-call-start", "retro/machines/c64.py",
           "at - first, stolen - stolen_before))", "at - first, stolen))", BUDGET_TESTS),
    Mutant("nested-interrupts-budgeted-apart", "retro/machines/c64.py",
           "            if not opened:\n", "            if True:\n", BUDGET_TESTS),
    # ---- the stability study (retro/analysis/study/stability) ------------------------------------
    Mutant("stability-full-speeds-to-40", "retro/analysis/study/stability/run.py",
           "FULL_SPEEDS = tuple(range(1, 65))", "FULL_SPEEDS = tuple(range(1, 41))", STABILITY_TESTS),
    Mutant("stability-reduced-speeds-to-16", "retro/analysis/study/stability/run.py",
           "REDUCED_SPEEDS = tuple(range(1, 25))", "REDUCED_SPEEDS = tuple(range(1, 17))", STABILITY_TESTS,
           explained="a size knob, not a rule: `--reduced` is documented only as fewer speeds; the report states "
                     "the highest speed tried and the tests derive every reduced figure from it"),
    Mutant("stability-wall-8-becomes-6", "retro/analysis/study/stability/tunnelling.py",
           "THICKNESSES = (1, 2, 4, 8)", "THICKNESSES = (1, 2, 4, 6)", STABILITY_TESTS),
    Mutant("stability-wall-off-centre", "retro/analysis/study/stability/tunnelling.py",
           "left = (width - thickness) // 2", "left = 0", STABILITY_TESTS),
    Mutant("stability-wrap-x-range-511", "retro/analysis/study/stability/wrap.py",
           "X_RANGE = 512  #", "X_RANGE = 511  #", STABILITY_TESTS),
    Mutant("stability-touching-is-one-apart", "retro/analysis/study/stability/edges.py",
           "BOX_CASES = {\"boxes touching (adjacent columns)\": SPRITE_W,",
           "BOX_CASES = {\"boxes touching (adjacent columns)\": SPRITE_W + 1,", STABILITY_TESTS),
    Mutant("stability-disc-radius2-56", "retro/analysis/study/stability/edges.py",
           "DISC_RADIUS2 = 49", "DISC_RADIUS2 = 56", STABILITY_TESTS),
    Mutant("stability-latch-read-line-250", "retro/analysis/study/stability/latch_pitfalls.py",
           "READ_LINE = 260", "READ_LINE = 250", STABILITY_TESTS),
    Mutant("stability-wrap-routine-truth-inclusive", "retro/analysis/study/stability/ranges.py",
           "truth = a < b + WRAP_W and b < a + WRAP_W", "truth = a <= b + WRAP_W and b <= a + WRAP_W",
           STABILITY_TESTS),
    Mutant("stability-report-safe-speed-off-by-one", "retro/analysis/study/stability/run.py",
           "body = [[charts.group_label(g, methods)] + [tunnelling.safe_speed(tunnel, g, t) for t",
           "body = [[charts.group_label(g, methods)] + [tunnelling.safe_speed(tunnel, g, t) + 1 for t",
           STABILITY_TESTS),
    Mutant("stability-report-wrap-columns-swapped", "retro/analysis/study/stability/run.py",
           "[[r.video.upper(), r.test, r.software_only, r.hardware_only,",
           "[[r.video.upper(), r.test, r.hardware_only, r.software_only,", STABILITY_TESTS),
    Mutant("stability-summary-wrap-software-only", "retro/analysis/study/stability/run.py",
           "{pal9.software_only + pal9.hardware_only}", "{pal9.software_only}", STABILITY_TESTS),
    Mutant("stability-report-range-wrong-column", "retro/analysis/study/stability/run.py",
           "[[r.routine, r.searched, r.cases, r.wrong, r.domain] for r in range_rows]",
           "[[r.routine, r.searched, r.cases, 0, r.domain] for r in range_rows]", STABILITY_TESTS),
    # ---- the field toolkit and the commands ------------------------------------------------------
    Mutant("fields-floats-are-integers", "retro/fields.py",
           "if isinstance(value, bool) or not isinstance(value, (int, str)) or",
           "if isinstance(value, bool) or not isinstance(value, (int, float, str)) or", FIELD_TESTS),
    Mutant("fields-bools-are-integers", "retro/fields.py",
           "if isinstance(value, bool) or not isinstance(value, (int, str)) or",
           "if not isinstance(value, (int, str)) or", FIELD_TESTS),
    Mutant("fields-unknown-keys-accepted", "retro/fields.py",
           "        if unknown:\n            raise self.error(join(field, unknown[0])",
           "        if False:\n            raise self.error(join(field, unknown[0])", FIELD_TESTS),
    Mutant("fields-flag-accepts-integers", "retro/fields.py",
           "        if not isinstance(value, bool):\n", "        if not isinstance(value, (bool, int)):\n", FIELD_TESTS),
    Mutant("check-exit-ignores-mismatches", "retro/commands/check.py",
           "return any(c.mismatches for c in checks)", "return False", COMMAND_TESTS),
    Mutant("run-json-drops-p", "retro/commands/run.py",
           "\"y\": r.y, \"s\": r.s, \"p\": r.p,", "\"y\": r.y, \"s\": r.s,", COMMAND_TESTS),
    Mutant("chip-free-handler-rti-not-a-return", "retro/routines/chip_access.py",
           "_reachable_code(read, entry, program, cpu, return_opcodes(handler))",
           "_reachable_code(read, entry, program, cpu, return_opcodes(False))",
           ("tests/routines/test_engine_reasons.py",)),
    Mutant("check-each-lane-stalled-said-always", "retro/commands/check.py",
           "if check.totals.stolen_max else \"no call stalled", "if True else \"no call stalled",
           ("tests/routines/test_engine_reasons.py",)),
    Mutant("check-runner-cache-ignores-edited-files", "retro/analysis/check/engines.py",
           "if cached is not None and reads_unchanged(cached[0]):", "if cached is not None:",
           ("tests/routines/test_runner_cache.py",)),
    Mutant("cached-reads-ignore-edited-files", "retro/fileio.py",
           "            if not reads_unchanged(reads):\n", "            if False:\n",
           ("tests/routines/test_runner_cache.py",)),
    Mutant("toml-writer-keys-never-quoted", "retro/fileio.py",
           "return key if _BARE_KEY.fullmatch(key) else _toml_string(key)", "return key",
           ("tests/formats/test_toml_writer.py",)),
    Mutant("toml-writer-control-characters-raw", "retro/fileio.py",
           "_TOML_ESCAPES.get(m[0], f\"\\\\u{ord(m[0]):04x}\")", "_TOML_ESCAPES.get(m[0], m[0])",
           ("tests/formats/test_toml_writer.py",)),
    # ---- the compiled engine's translator (retro/cpu/translate.py, compiled_ops.py) -----------------
    Mutant("compiled-page-penalty-dropped", "retro/cpu/translate.py",
           'self.put(f"cycles += {base} + {crossed} * {PAGE_CROSS_CYCLES}")', 'self.put(f"cycles += {base}")',
           COMPILED_TESTS),
    Mutant("compiled-branch-page-cycle-dropped", "retro/cpu/translate.py",
           "return BRANCH_TAKEN_CYCLES + (BRANCH_PAGE_CYCLES if", "return BRANCH_TAKEN_CYCLES + (0 if",
           COMPILED_TESTS),
    Mutant("compiled-nmos-decimal-high-adjust-off-by-one", "retro/cpu/compiled_ops.py",
           "    if high >= 0xA0:", "    if high > 0xA0:", COMPILED_TESTS),
    Mutant("compiled-store-into-code-trusted", "retro/cpu/translate.py",
           'self.put("bad |= code_map[t]")', 'self.put("bad |= 0")', COMPILED_TESTS),
    # ---- the superoptimiser (retro/optimize/) ------------------------------------------------------
    Mutant("optimize-free-registers-zero", "retro/optimize/evaluate.py",
           "                entry = (registers, bits, state.free_mask)", "                entry = None",
           ("tests/optimize/test_optimize.py::test_a_candidate_relying_on_x_zero_at_entry_is_rejected",)),
    Mutant("optimize-proof-ignores-cycles", "retro/optimize/evaluate.py",
           " & (base.cycles == varied.cycles)", "",
           ("tests/optimize/test_optimize.py::test_a_candidate_whose_cycles_depend_on_the_free_carry_is_rejected",)),
    Mutant("optimize-rts-keeps-everything-live", "retro/optimize/effects.py",
           "            if name == \"RTS\" or local_jump:\n                incoming = out\n",
           "            if name == \"RTS\":\n                incoming = everything\n            elif local_jump:\n"
           "                incoming = out\n",
           ("tests/optimize/test_optimize.py::test_liveness_frees_what_the_routine_overwrites_and_keeps_the_outputs",)),
    Mutant("optimize-branch-edge-facts-swapped", "retro/optimize/facts.py",
           '("const", flag, value if taken else 1 - value)', '("const", flag, value)',
           ("tests/optimize/test_wasteful.py::test_facts_know_the_carry_a_branch_and_a_compare_leave",)),
    Mutant("optimize-facts-check-skipped", "retro/optimize/optimizer.py",
           'if kind == "window" and self.prover.kind != "exhaustive" and not window_agrees(',
           'if False and not window_agrees(',
           ("tests/optimize/test_wasteful.py::test_a_wasteful_aabb8_result_passes_the_exhaustive_sweep",)),
    Mutant("optimize-compare-carry-fact-ignored", "retro/optimize/facts.py",
           "            keep &= values[\"C\"] == (values[fact[1]] >= _value_of(fact[2], values))", "            pass",
           ("tests/optimize/test_wasteful.py::test_a_window_change_wrong_on_an_unsampled_state_is_refused",)),
    Mutant("optimize-branch-over-jmp-not-inverted", "retro/optimize/flow.py",
           'inverted = Instruction(INVERSE[instruction.mnemonic], "rel"',
           'inverted = Instruction(instruction.mnemonic, "rel"',
           ("tests/optimize/test_wasteful.py::test_a_branch_over_a_jmp_is_inverted_and_a_jmp_to_the_next_dropped",)),
    Mutant("optimize-no-indexed-windows", "retro/optimize/effects.py",
           "    return (indexed and instruction.mode in INDEXED_READ_MODES", "    return (False and instruction.mode in INDEXED_READ_MODES",
           ("tests/optimize/test_wasteful.py::test_a_window_reads_through_an_index",)),
    Mutant("smt-decimal-adc-carry-threshold", "retro/optimize/smt.py",
           "z3.UGT(adjusted & 0xFF0, 0xF0)", "z3.UGT(adjusted & 0xFF0, 0x100)",
           ("tests/optimize/test_smt.py::test_each_translated_opcode_agrees_with_the_machine_on_random_states",)),
    Mutant("smt-zero-page-index-does-not-wrap", "retro/optimize/smt.py",
           "return _wide(byte(operand) + index), no", "return word(operand) + _wide(index), no",
           ("tests/optimize/test_smt.py::test_each_translated_opcode_agrees_with_the_machine_on_random_states",)),
    Mutant("smt-branch-page-cycle-dropped", "retro/optimize/smt.py",
           "(BRANCH_PAGE_CYCLES if crossed else 0)", "0",
           ("tests/optimize/test_smt.py::test_each_translated_opcode_agrees_with_the_machine_on_random_states",)),
    Mutant("smt-live-flags-not-compared", "retro/optimize/smt.py",
           "    parts += [before.flags[n] != after.flags[n] for n in FLAG_NAMES if n in live]\n", "",
           ("tests/optimize/test_smt.py::test_flags_left_live_must_match_too",)),
    Mutant("smt-counterexample-not-replayed", "retro/optimize/optimizer.py",
           "                self.samples.add(columns, expected, index, witness)",
           "                pass",
           ("tests/optimize/test_smt.py::test_a_wrong_candidate_the_cases_miss_is_refuted_and_its_counterexample_joins_the_samples",)),
    Mutant("smt-refuted-routine-admitted", "retro/optimize/optimizer.py",
           '                if fails or verdict.scope == "routine":', "                if fails:",
           ("tests/optimize/test_smt.py::test_a_routine_z3_refutes_in_the_domain_is_refused_though_the_core_passes_it",)),
    Mutant("smt-chain-trusts-the-last-change", "retro/optimize/optimizer.py",
           "    if all(change.proof.kind == \"smt\" for change in outcome.changes):", "    if True:",
           ("tests/optimize/test_smt.py::test_the_result_is_smt_only_when_every_change_on_the_way_was",)),
    Mutant("smt-no-slower-from-the-cases-only", "retro/optimize/optimizer.py",
           'slower = proof.slower or (verdict.scope == "routine" and result.no_slower is False)', "slower = proof.slower",
           ("tests/optimize/test_smt.py::test_a_change_slower_on_one_input_in_2_to_the_16_is_slower_by_z3_though_no_case_shows_it",)),
    Mutant("smt-jmp-cycles-dropped", "retro/optimize/smt.py",
           '            went.cycles = here.cycles + _op(fragment.cpu, "JMP", "abs").cycles',
           "            went.cycles = here.cycles",
           ("tests/optimize/test_smt.py::test_a_forward_jmp_is_an_edge_z3_follows_with_its_three_cycles",)),
    Mutant("smt-compare-carry-strict", "retro/optimize/smt.py",
           '    elif name in COMPARES:\n        register, value = getattr(state, COMPARES[name]), operand()\n        state.flags["C"] = z3.UGE(register, value)',
           '    elif name in COMPARES:\n        register, value = getattr(state, COMPARES[name]), operand()\n        state.flags["C"] = z3.UGT(register, value)',
           ("tests/optimize/test_smt.py::test_each_translated_opcode_agrees_with_the_machine_on_random_states",)),
    Mutant("smt-domain-ranges-dropped", "retro/optimize/smt.py",
           "            facts += [z3.UGE(value, lo), z3.ULE(value, hi)]", "            pass",
           ("tests/optimize/test_smt.py::test_z3_proves_on_the_specs_domain_not_past_it",)),
    Mutant("tables-bytes-not-reported", "retro/optimize/report.py",
           '"bytes": size + tables,', '"bytes": size,',
           ("tests/optimize/test_tables.py::test_the_lookup_is_found_when_the_table_is_allowed_and_its_bytes_are_counted",)),
    Mutant("tables-bytes-not-weighed", "retro/optimize/optimizer.py",
           "        return code_bytes(listing) + table_bytes(listing, self.tables)", "        return code_bytes(listing)",
           ("tests/optimize/test_tables.py::test_a_table_does_not_pay_for_itself_in_bytes",)),
    Mutant("compiled-65c02-decimal-cycle-dropped", "retro/cpu/translate.py",
           '                self.put("cycles += fd")', '                pass', COMPILED_TESTS),
    Mutant("compiled-binary-sbc-not-complemented", "retro/cpu/translate.py",
           'operand = f"({value} ^ 255)" if name == "sbc" else value', 'operand = value', COMPILED_TESTS),
    Mutant("compiled-decimal-free-despite-plp", "retro/cpu/translate.py",
           'op.mnemonic in ("SED", "PLP") for op in instructions', 'op.mnemonic in ("SED",) for op in instructions',
           COMPILED_TESTS),
    Mutant("compiled-decimal-entry-not-left", "retro/cpu/translate.py",
           'bad="fd * 2" if e.binary and e.adds else "0"', 'bad="0"', COMPILED_TESTS),
    Mutant("compiled-unknown-block-returns", "retro/cpu/translate.py",
           'e.put(f"    status = {FALLBACK_JUMP}")\n    e.put("    break")\n    name = "run_calls"',
           'e.put("    status = 0")\n    e.put("    break")\n    name = "run_calls"', COMPILED_TESTS),
    Mutant("compiled-flag-input-ignored", "retro/cpu/translate.py",
           'lines.append(f"p |= {shift} if cols[{column}][lane] != 0 else 0")', 'pass', COMPILED_TESTS),
    Mutant("compiled-register-input-shift-dropped", "retro/cpu/translate.py",
           'lines.append(f"{SET_REGISTERS[what]} |= (cols[{column}][lane] >> {shift}) & 255")',
           'lines.append(f"{SET_REGISTERS[what]} |= cols[{column}][lane] & 255")',
           COMPILED_TESTS + ("tests/routines/test_compiled_check.py",)),
    Mutant("compiled-taken-branch-cycle-dropped", "retro/cpu/translate.py",
           "return BRANCH_TAKEN_CYCLES + (", "return 0 + (", COMPILED_VECTOR_TESTS),
    Mutant("compiled-6510-decimal-ignored", "retro/cpu/translate.py",
           'self.decimal = cpu == "6510"', 'self.decimal = False', COMPILED_VECTOR_TESTS),
    Mutant("compiled-2a03-decimal-applied", "retro/cpu/translate.py",
           'self.decimal = cpu == "6510"', 'self.decimal = cpu in ("6510", "2a03")', COMPILED_VECTOR_TESTS),
    Mutant("compiled-lax-x-not-loaded", "retro/cpu/translate.py",
           '                self.put("x = a")', '                pass', COMPILED_VECTOR_TESTS),
    Mutant("compiled-compare-carry-inverted", "retro/cpu/translate.py",
           'self.put("fc = ((t >> 8) & 1) ^ 1")', 'self.put("fc = (t >> 8) & 1")', COMPILED_VECTOR_TESTS),
    Mutant("compiled-jsr-pushes-next-instruction", "retro/cpu/translate.py",
           "back = (pc + 2) & WORD", "back = (pc + 3) & WORD", COMPILED_VECTOR_TESTS),
    Mutant("compiled-direct-return-despite-stack-moves", "retro/cpu/translate.py",
           "op.mnemonic in STACK_MNEMONICS for op in instructions", "op.mnemonic in () for op in instructions",
           COMPILED_TESTS),
    Mutant("compiled-direct-return-despite-computed-stores", "retro/cpu/translate.py",
           "return (lanes is not None and not computed_writes", "return (lanes is not None", COMPILED_TESTS),
    Mutant("compiled-direct-return-despite-fixed-stack-stores", "retro/cpu/translate.py",
           "for address in (*fixed_writes, *placed, *lanes)", "for address in (*placed, *lanes)", COMPILED_TESTS),
    Mutant("compiled-jump-to-itself-unchecked", "retro/cpu/translate.py",
           "    if address <= e.pc:\n        _loop_check(e)", "    if address < e.pc:\n        _loop_check(e)",
           COMPILED_TESTS),
    Mutant("compiled-whole-memory-restore-skipped", "retro/cpu/translate.py",
           "                mem[k] = image[k]", "                pass", COMPILED_TESTS),
    Mutant("compiled-return-arm-goes-to-the-entry", "retro/cpu/translate.py",
           'e.put(f"blk = {e.return_arm}  # the return arm")', 'e.put("blk = 0  # the return arm")', COMPILED_TESTS),
    Mutant("compiled-jump-to-no-block-taken-for-the-budget", "retro/cpu/translate.py",
           "            elif blk < 0:\n", "            elif blk < -5:\n", COMPILED_TESTS),
    Mutant("compiled-stopped-write-taken-for-the-budget", "retro/cpu/translate.py",
           "status = {fallback_write} if bad else {budget_status}", "status = {budget_status}", COMPILED_TESTS),
    Mutant("compiled-cycles-merged-across-a-read", "retro/cpu/translate.py",
           ' or ("cycles" in line and not constant)', "", COMPILED_TESTS + IFCONV_TESTS),
    Mutant("ifconv-negative-choice-from-the-wrong-bit", "retro/cpu/translate.py",
           'BRANCH_VALUES = {0x80: "nv >> 7"', 'BRANCH_VALUES = {0x80: "(nv >> 6) & 1"', IFCONV_TESTS + COMPILED_TESTS),
    Mutant("compiled-output-shift-lost", "retro/routines/batch_runs.py",
           'return self._with("<<", other)', 'return self._with("|", other)', ("tests/routines/test_compiled_check.py",)),
    # ---- if-conversion (retro/cpu/ifconvert.py, translate.py's `_emit_converted`) ----------------------
    Mutant("ifconv-store-made-on-both-ways", "retro/cpu/translate.py",
           "        if self.guard is not None:  # a converted way's store", "        if False:  # a converted way's store",
           IFCONV_TESTS),
    Mutant("ifconv-nested-store-ignores-the-outer-way", "retro/cpu/translate.py",
           'within = "" if e.guard is None else f"{e.guard} & "', 'within = ""', IFCONV_TESTS),
    Mutant("ifconv-taken-way-starts-from-the-other-ways-state", "retro/cpu/translate.py",
           '+ [f"{e.indent}{name} = s{k}_{name}" for name in fall_writes])', ")", IFCONV_TESTS),
    Mutant("ifconv-selection-inverted", "retro/cpu/translate.py",
           'e.put(f"{name} = choose({taken}, {name}, f{k}_{name})")',
           'e.put(f"{name} = choose({taken}, f{k}_{name}, {name})")', IFCONV_TESTS),
    Mutant("ifconv-select-picks-the-other", "retro/cpu/compiled_ops.py",
           "return builder.select(flag, taken_value, other_value)", "return builder.select(flag, other_value, taken_value)",
           IFCONV_TESTS),
    Mutant("ifconv-taken-cycles-dropped", "retro/cpu/translate.py",
           '    if extra:\n        e.put(f"cycles += {extra}")', "    if extra:\n        pass", IFCONV_TESTS),
    Mutant("ifconv-computed-store-in-a-way", "retro/cpu/translate.py",
           'if stores and op.mode not in ("zpg", "abs"):', "if False:", IFCONV_TESTS),
    Mutant("ifconv-one-way-to-rts-is-enough", "retro/cpu/ifconvert.py",
           "        if taken.end == RTS_JOIN and fall.end == RTS_JOIN:", "        if taken.end == RTS_JOIN or fall.end == RTS_JOIN:",
           IFCONV_TESTS),
    Mutant("ifconv-merged-exit-direction-inverted", "retro/cpu/translate.py",
           'e.put(f"{into} = u" if branch_target(pc, offset, length) == towards else f"{into} = u ^ 1")',
           'e.put(f"{into} = u ^ 1" if branch_target(pc, offset, length) == towards else f"{into} = u")', IFCONV_TESTS),
    Mutant("ifconv-merged-exit-cycles-dropped", "retro/cpu/translate.py",
           'e.put(f"cycles += {_taken_cycles(pc, length, offset)} * u")', "pass", IFCONV_TESTS),
    Mutant("ifconv-merged-exit-of-the-other-way", "retro/cpu/translate.py",
           'e.put(f"e{k} = choose({taken}, e{k}t, e{k}f)")', 'e.put(f"e{k} = choose({taken}, e{k}f, e{k}t)")',
           IFCONV_TESTS),
    Mutant("compiled-rts-without-plus-one", "retro/cpu/translate.py",
           'e.put("t = ((u << 8 | t) + 1) & 65535")', 'e.put("t = (u << 8 | t) & 65535")', COMPILED_VECTOR_TESTS),
    # ---- each Machine call starts from the code as loaded; stated facts stay off the compiled engine --------
    Mutant("machine-call-keeps-patched-code", "retro/routines/runner.py",
           "        self._restore_code()\n        if self.start is not None:",
           "        if self.start is not None:", ("tests/routines/test_static_smc.py",)),
    Mutant("compiled-takes-stated-facts", "retro/analysis/check/engines.py",
           "    if runner.watched_facts:  # Machine", "    if False:  # Machine",
           ("tests/routines/test_compiled_check.py",)),
    # self-modifying code that patches operands (translate.live_operands)
    Mutant("compiled-smc-store-into-opcode-taken", "retro/cpu/translate.py",
           '        if address in instructions:\n            raise Untranslatable(why + "an opcode byte',
           '        if address in ():\n            raise Untranslatable(why + "an opcode byte', COMPILED_TESTS),
    Mutant("compiled-smc-branch-offset-taken-as-live", "retro/cpu/translate.py",
           'return op.mode not in ("rel", "zpr") and op.mnemonic != "JSR"', 'return op.mnemonic != "JSR"', COMPILED_TESTS),
    Mutant("compiled-smc-patched-high-byte-folded", "retro/cpu/translate.py",
           'return "w", (f"(w | ({_read((pc + 2) & WORD)} << 8))"', 'return "w", (f"(w | (3 << 8))"', COMPILED_TESTS),
    Mutant("compiled-smc-patched-low-byte-page-crossing-from-zero", "retro/cpu/translate.py",
           'self.put(f"pg = ({lo} + {index}) >> 8")',
           'self.put(f"pg = ({0 if lo == \'w\' else lo} + {index}) >> 8")', COMPILED_TESTS),
    Mutant("compiled-smc-rmw-patch-not-live", "retro/cpu/translate.py",
           'WRITERS = {"STA", "STX", "STY", "SAX", "STZ", "ASL", "LSR", "ROL", "ROR", "INC", "DEC",',
           'WRITERS = {"STA", "STX", "STY", "SAX", "STZ",', COMPILED_TESTS),
    Mutant("compiled-smc-computed-store-onto-live-byte-falls-back", "retro/cpu/compiled.py",
           "code_map[list(translation.code_bytes - translation.live_bytes)] = 1",
           "code_map[list(translation.code_bytes)] = 1", COMPILED_TESTS),
    Mutant("compiled-smc-patched-jmp-target-inlined", "retro/cpu/translate.py",
           "    returned_to = {_successors(pc, instructions[pc], read)[0][0] for pc in live",
           "    returned_to = {_successors(pc, instructions[pc], read)[0][0] for pc in ()", COMPILED_TESTS),
    Mutant("compiled-smc-patched-absolute-address-ignored", "retro/cpu/translate.py",
           '                self.put(f"ea = {word}")\n                return "ea", None',
           '                self.put(f"ea = {word}")\n                return 0x0300, None', COMPILED_TESTS),
    Mutant("compiled-live-store-converted", "retro/cpu/translate.py",
           "    fixed = {pc: (None if pc in live else op) for pc, op in instructions.items()}",
           "    fixed = instructions", ("tests/cpu/test_compiled_ifconvert.py",)),
    Mutant("compiled-many-known-lanes-one-line-each", "retro/cpu/translate.py",
           "    if lanes is None or len(lanes) > LINES_LIMIT:", "    if lanes is None:", COMPILED_TESTS),
    # ---- per-block overhead and start-up (blocks) ------------------------------------------------------
    Mutant("compiled-entered-image-kept-after-a-new-call-image", "retro/routines/batch_runs.py",
           "    if held is None or held[0] != s or held[1] != runner.call_image:",
           "    if held is None or held[0] != s:", ("tests/routines/test_compiled_check.py",)),
    Mutant("cli-one-command-builds-every-parser", "retro/cli.py",
           "    parser = build_parser(argv[0] if argv and argv[0] in COMMANDS else None)",
           "    parser = build_parser(None)", ("tests/test_commands.py",)),
    Mutant("coverage-merge-skips-a-block-that-ran-code", "retro/analysis/coverage_model.py",
           "        if other.worst_cycles is None and not any((other.executed,",
           "        if other.worst_cycles is None and any((other.executed,", ("tests/routines/test_code_coverage.py",)),
    Mutant("where-constant-term-not-spread", "retro/routines/where.py",
           "    return truth if truth.shape == (n,) else np.broadcast_to(truth, (n,))",
           "    return truth", ("tests/routines/test_where.py",)),
    # table columns that are one row repeated (grid.repeated_row) and their readers' one-row paths
    Mutant("one-row-without-the-zero-stride", "retro/routines/grid.py",
           "if column.ndim != 2 or not len(column) or column.strides[0] != 0:",
           "if column.ndim != 2 or not len(column):", TABLE_ROW_TESTS),
    Mutant("pixel-one-pair-from-the-block-s-ends", "retro/routines/builtin_cases.py",
           "if len(pair) and pair.min() == pair.max():", "if len(pair) and pair[0] == pair[-1]:", TABLE_ROW_TESTS),
    Mutant("pixel-one-pair-when-either-column-is-one-row", "retro/routines/builtin_cases.py",
           "if row_a is not None and row_b is not None:", "if row_a is not None or row_b is not None:",
           TABLE_ROW_TESTS),
    Mutant("lane-bytes-of-one-row-from-its-first-byte", "retro/routines/batch_runs.py",
           "= same.astype(np.uint8)[:, None]", "= same[:1].astype(np.uint8)[:, None]", TABLE_ROW_TESTS),
    Mutant("lane-byte-rows-a-power-of-two-apart", "retro/routines/batch_runs.py",
           "return CACHE_LINE * (lines + 1 - lines % 2)", "return CACHE_LINE * lines", TABLE_ROW_TESTS),
    Mutant("pixel-distinct-rows-trust-the-hash", "retro/routines/builtin_cases.py",
           "if (distinct[which.ravel()] == rows).all():", "if True:", TABLE_ROW_TESTS),
    Mutant("one-row-column-checked-at-its-first-value", "retro/routines/cases.py",
           "        column = row\n", "        column = row[:1]\n", TABLE_ROW_TESTS),
]


def copy_tree(destination: Path) -> Path:
    ignore = shutil.ignore_patterns(".git", ".venv", "v", "build", "*.egg-info", "__pycache__", ".pytest_cache",
                                    ".hypothesis", "retro-out", "out")
    shutil.copytree(ROOT, destination, ignore=ignore)
    return destination


KILLERS = Path(os.environ.get("RETRO_MUTANT_KILLERS", Path.home() / ".cache" / "retro" / "mutant-killers.json"))


def _pytest(tree: Path, arguments: list[str]) -> tuple[int, list[str], str]:
    """Run pytest in the mutated tree: its exit status, the failing test ids, and its last words."""
    env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1",
           "RETRO_CPU_VECTORS": os.environ.get("RETRO_CPU_VECTORS", str(ROOT.parent / "shared" / "cpu-vectors"))}
    done = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *arguments],
                          cwd=tree, env=env, capture_output=True, text=True, timeout=TIMEOUT_SECONDS)
    failed = [line.split(" ", 2)[1] for line in done.stdout.splitlines() if line.startswith(("FAILED ", "ERROR "))]
    return done.returncode, failed, (done.stderr or done.stdout).strip()[-120:]


def _guards(mutant: Mutant, test_id: str) -> bool:
    """Whether a test id lies inside the mutant's own guard set (only those may kill it)."""
    path = test_id.split("::")[0]
    return any(path == t.split("::")[0] or path.startswith(t.rstrip("/") + "/") for t in mutant.tests)


def _killer_first(mutant: Mutant, tree: Path, killers: dict[str, str]) -> str | None:
    """The test that killed this mutant last time, run alone first: a mutant it kills again is killed
    without running the whole guard set (the full set still runs when it does not)."""
    known = killers.get(mutant.name)
    if not known or not _guards(mutant, known) or not (tree / known.split("::")[0]).exists():
        return None
    status, failed, _ = _pytest(tree, ["-n", "0", known])
    if status == 1 and failed:
        return f"killed by {failed[0].split('::')[-1][:60]}"
    return None


def run_mutant(mutant: Mutant, tree: Path, killers: dict[str, str] | None = None) -> tuple[str, float]:
    killers = {} if killers is None else killers
    path = tree / mutant.file
    original = path.read_text()
    if original.count(mutant.old) != 1:
        return f"STALE (the text to change occurs {original.count(mutant.old)} times)", 0.0
    path.write_text(original.replace(mutant.old, mutant.new))
    started = time.monotonic()
    try:
        verdict = _killer_first(mutant, tree, killers)
        if verdict is None:
            status, failed, last = _pytest(tree, list(mutant.tests))
            if status in PYTEST_NOT_RUN:  # a usage error or no test collected proves nothing
                verdict = f"BROKEN (pytest exit {status}: {last})"
            else:
                verdict = (f"killed by {failed[0].split('::')[-1][:60]}" if failed else "killed") if status else "SURVIVED"
                if status and failed:
                    killers[mutant.name] = failed[0]
    except subprocess.TimeoutExpired:
        verdict = "killed (timeout)"
    finally:
        path.write_text(original)
    return verdict, time.monotonic() - started


def _load_killers() -> dict[str, str]:
    try:
        return json.loads(KILLERS.read_text())
    except (OSError, ValueError):
        return {}


def _save_killers(killers: dict[str, str]) -> None:
    KILLERS.parent.mkdir(parents=True, exist_ok=True)
    staged = KILLERS.with_suffix(".tmp")
    staged.write_text(json.dumps(killers, indent=1, sort_keys=True))
    staged.replace(KILLERS)


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
    missing = sorted({t for m in chosen for t in m.tests if not (ROOT / t.split("::")[0]).exists()})
    if missing:
        print(f"mutants: test path {missing[0]!r} does not exist", file=sys.stderr)
        return 2
    failures = 0
    with tempfile.TemporaryDirectory(prefix="retro-mutants-") as tmp:
        tree = copy_tree(Path(tmp) / "tree")
        print("| mutant | file | verdict | seconds |\n|---|---|---|---|", flush=True)
        killers = _load_killers()
        for mutant in chosen:
            verdict, seconds = run_mutant(mutant, tree, killers)
            _save_killers(killers)
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
