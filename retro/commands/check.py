"""`retro check`: cross-check routines (built-in names or users' spec files) against their references:
results, cycles (against the timing model) and static bounds; exit 1 on any mismatch."""

from __future__ import annotations

import inspect
import math
from pathlib import Path
from typing import TYPE_CHECKING

from retro.analysis.check import RoutineCheck, inputs_by_name, run_checks
from retro.analysis.check.coverage import coverage_line, coverage_record, summary
from retro.analysis.check.entry_runs import VARIANTS
from retro.analysis.check.results import describe_case, describe_outputs, entry_needs
from retro.analysis.check.search import CYCLES_PER_CANDIDATE, DEFAULT_SEARCH, STALE_GENERATIONS
from retro.analysis.raster import format_raster, raster_figures
from retro.analysis.row_check import rows_lines, rows_record
from retro.errors import InputError
from retro.fileio import command_files, output_folder, read_text, write_all_atomic, write_atomic
from retro.numbers import parse_int
from retro.progress import Progress, quiet
from retro.routines import cases as case_sets
from retro.routines.entry import EntryState
from retro.chips.ppu.constants import DOTS_PER_LINE
from retro.machines.nes import position_after
from retro.routines.chip_access import FREE_REASON, NesStart
from retro.workers import MAX_WORKERS, configured
import argparse
from retro.analysis.check import AGREEMENT_PER_PART, AUTO_BATCH_CASES
from retro.analysis.check.engines import AUTO_COMPILED_CYCLES
from retro.commands import options
from retro.progress import progress_printer
from retro.routines.registry import builtin_names
from retro.routines.spec import MAX_SEARCH

if TYPE_CHECKING:  # (the reports and JUnit are imported where written: a check without them never loads them)
    from retro.reports.annotated import Annotated, RoutineCode

MAX_RANDOM = 10 ** 9
MAX_JOBS = MAX_WORKERS
JSON_EXACT = 1 << 53  # larger whole numbers lose digits in JSON readers that use doubles


def check(routines: list[str] | None = None, *, exhaustive: bool = False, seed: int | str | None = None,
          random: int | str | None = None, jobs: int | str | None = None, scene: str | Path | None = None,
          at_line: int | str | None = None, at_cycle: int | str | None = None, engine: str = "auto",
          progress: Progress = quiet, bounded_product: int = case_sets.BOUNDED_PRODUCT,
          search: int | str | None = None, at_dot: int | str | None = None, in_nmi: bool = False,
          scheduler: str | None = None) -> list[RoutineCheck]:
    """Check each routine (all built-ins when none is named). `random`: random cases per routine
    (default: the spec's count, bounded without `exhaustive`); `scene` runs every call on a C64 with
    that VIC-II scene from `at_line`/`at_cycle` (default: the scene's [cpu] start), or on a NES with that
    NES scene from scanline `at_line`, dot `at_dot` (default 0, 0), or `in_nmi` as the NMI handler; `search`: candidates
    of the coverage-guided search (default: the spec's `[cases] search`, else 4,096; 0: none); `scheduler`: a
    Dask scheduler's address for the parallel work (default: $RETRO_SCHEDULER, else local workers)."""
    return run_checks(
        routines, exhaustive=exhaustive,
        seed=None if seed is None else parse_int(seed, field="--seed", lo=0, hi=2 ** 63 - 1),
        random_count=None if random is None else parse_int(random, field="--random", lo=0, hi=MAX_RANDOM),
        jobs=configured(None if jobs is None else parse_int(jobs, field="--jobs", lo=1, hi=MAX_JOBS), scheduler),
        progress=progress, start=options.scene_start(scene, at_line, at_cycle, at_dot, in_nmi), bounded_product=bounded_product, engine=engine,
        search_budget=None if search is None else parse_int(search, field="--search", lo=0, hi=MAX_SEARCH))


def failed(checks: list[RoutineCheck]) -> bool:
    """Whether any routine gave a wrong result, a wrong cycle count or broke its budget or bounds."""
    return any(c.mismatches for c in checks)


def as_json(checks: list[RoutineCheck]) -> list[dict]:
    return [check_record(c) for c in checks]


def lines(checks: list[RoutineCheck]) -> list[str]:
    return [line for c in checks for line in format_check(c)]


# ---- reports: the text and JSON of a routine's check -----------------------------------------------
def coverage(check: RoutineCheck) -> list[dict]:
    out = []
    for part in check.parts:
        item = {"part": part.name, "cases": part.cases}
        if part.name == "exhaustive":
            item["space"] = part.total
            item["inputs"] = list(check.routine.exhaustive)
            item["complete"] = part.cases == part.total
            if part.inside is not None:  # only the combinations inside the domain ran
                item["inside"] = part.inside
                item["complete"] = part.cases == part.inside
        out.append(item)
    return out


def cycle_figures(check: RoutineCheck) -> dict:
    """The cycle fields shared by `retro check --json` and `retro cycles --json`."""
    t = check.totals
    routine = check.routine
    return {"min": t.cycles_min, "mean": round(check.mean, 2), "max": t.cycles_max,
            "static_min": check.static.best if check.static else None,
            "static_max": check.static.worst if check.static else None,
            "min_inputs": inputs_by_name(routine, t.min_case) if t.min_case is not None else None,
            "max_inputs": inputs_by_name(routine, t.max_case) if t.max_case is not None else None,
            "budget": routine.budget, "vblank": vblank_record(check),
            "raster": {**raster_figures(routine.machine, t.cycles_min, check.mean if t.cycles_count else None,
                                        t.cycles_max), **scene_raster(check)}}


def scene_raster(check: RoutineCheck) -> dict:
    """With --scene: the calls on the scene's timeline from the start line ({"scene": {...}}), stalls
    included: lines taken, the most cycles stolen, and where the slowest call ended."""
    start = check.start
    t = check.totals
    if start is None or not t.cycles_count:
        return {}
    if isinstance(start, NesStart):
        return {"scene": nes_scene_raster(check)}
    video = start.scene.state.video
    per_line = video.cycles_per_line
    last = start.line * per_line + start.cycle - 1 + t.cycles_max - 1
    frames, within = divmod(last, video.frame_cycles)
    end_line, end_cycle = divmod(within, per_line)
    return {"scene": {"chip": video.chip, "start_line": start.line, "start_cycle": start.cycle,
                      "min_lines": round(t.cycles_min / per_line, 3), "mean_lines": round(check.mean / per_line, 3),
                      "max_lines": round(t.cycles_max / per_line, 3), "stolen_max": t.stolen_max,
                      "slowest_end_line": end_line, "slowest_end_cycle": end_cycle + 1, "frames_crossed": frames}}


def nes_scene_raster(check: RoutineCheck) -> dict:
    """The calls on a NES scene's frame: where they start (scanline, dot, or the NMI), scanlines taken
    (341 dots each), the most cycles OAM DMA held the CPU, and where the slowest returned."""
    start, t = check.start, check.totals
    video = start.scene.video
    entry = start.entry(check.routine.world.enter)
    per_line = DOTS_PER_LINE / video.dots_per_cpu_cycle
    end_line, end_dot, frames = position_after(video, entry, t.cycles_max)
    return {"chip": "ppu", "video": video.name, "start_line": entry.line, "start_dot": entry.dot,
            "in_nmi": entry.in_nmi, "min_lines": round(float(t.cycles_min / per_line), 3),
            "mean_lines": round(float(check.mean / per_line), 3), "max_lines": round(float(t.cycles_max / per_line), 3),
            "stolen_max": t.stolen_max, "slowest_end_line": end_line, "slowest_end_dot": end_dot,
            "frames_crossed": frames}


def vblank_record(check: RoutineCheck) -> dict | None:
    """With a NES scene: the CPU cycles from the calls' start to the pre-render line (where rendering
    starts: the vblank budget of a call entered in vblank) and what the fastest and slowest call
    leave of them (negative: it ran into rendering), OAM DMA counted. None otherwise."""
    start, t = check.start, check.totals
    if not isinstance(start, NesStart) or not t.cycles_count:
        return None
    budget = start.entry(check.routine.world.enter).rendering_cycles
    return {"budget": budget, "best_left": budget - t.cycles_min, "worst_left": budget - t.cycles_max,
            "oam_dma_max": t.stolen_max}


def check_record(check: RoutineCheck) -> dict:
    """One routine's check as plain data (what `retro check --json` prints)."""
    t = check.totals
    record = {"routine": check.routine.name, "spec": check.routine.shown_path or str(check.routine.spec_path), "cpu": check.routine.cpu,
              "machine": check.routine.machine, "cases": t.cases, "mismatches": check.mismatches,
              "result_mismatches": t.result_mismatches,
              "cycle_mismatches": t.cycle_mismatches + (check.agreement.cycle_mismatches if check.agreement else 0),
              "run_errors": t.run_errors, "bounds_violations": check.bounds_violations,
              "budget_violations": check.budget_violations,
              "outside_domain": t.outside, "outside_domain_wrong": t.outside_wrong,
              "domain": [{"condition": c.text, "cases": t.constraint_cases.get(c.text, 0),
                          "wrong": t.constraint_wrong.get(c.text, 0)} for c in check.routine.domain],
              **cycle_figures(check), "cpu_min": t.cpu_min, "cpu_max": t.cpu_max,  # stalls excluded: what static bounds
              "static_modified": list(check.static.modified) if check.static else [],
              "worst_reached": check.worst_reached, "coverage": coverage(check),
              "input_space": space if (space := check.routine.input_space()) < JSON_EXACT else None,
              "input_space_log2": round(math.log2(space), 3), "coverage_argument": check.routine.coverage or None,
              "examples": t.examples, "outside_examples": t.outside_examples, "engine": check.engine,
              "engine_note": check.engine_note or None,
              "engine_reason": check.engine_reason, "compile_seconds": None if check.compile_seconds is None else
              round(check.compile_seconds, 3), "compiled_fallbacks": fallback_counts(t),
              "engine_agreement": None if check.agreement is None else {
                  "cases": check.agreement.engine_cases, "mismatches": check.agreement.engine_mismatches,
                  "timing_model_mismatches": check.agreement.cycle_mismatches},
              "notes": list(check.routine.notes), "first_failure": None, "rows": None,
              "code_coverage": None if check.code_coverage is None else coverage_record(
                  summary(check.code_coverage, check.routine.program)),
              "search": search_record(check), "bounds_reached": bounds_reached(check),
              "entry_dependence": entry_record(check), "random_draw": draw_record(check.random_draw)}
    failure = t.failure
    if failure is not None:
        routine = check.routine
        record["first_failure"] = {
            "kind": failure.kind, "inputs": inputs_by_name(routine, failure.case),
            "outputs": None if failure.outputs is None else dict(zip(routine.output_names, _plain(failure.outputs))),
            "expected": None if failure.expected is None else {  # None: an output an expected row does not state
                name: value for name, value in zip(routine.output_names, _plain(failure.expected))
                if value is not None},
            "message": failure.message, "trace": check.trace}
    if check.rows is not None:
        record["rows"] = rows_record(check.routine, check.rows)
    return record


def fallback_counts(t) -> dict[str, int]:
    """The compiled engine's calls that ran on the batched core, by reason (the reason's text)."""
    if not t.fallbacks:  # (no import of the compiled engine, numba's 0.2 s, for a check that had none)
        return {}
    from retro.cpu.compiled import FALLBACK_REASON

    return {FALLBACK_REASON.get(code, str(code)): count for code, count in sorted(t.fallbacks.items())}


def engine_lines(check: RoutineCheck) -> list[str]:
    """Which engine ran and why, when the compiled engine was asked for or considered."""
    if check.engine != "compiled" and "compiled" not in check.engine_reason:
        return []
    line = f"  engine: {check.engine} ({check.engine_reason})"
    if check.compile_seconds is not None:
        line += f"; code compiled or loaded from the cache in {check.compile_seconds:.2f} s"
    lines = [line]
    for reason, count in fallback_counts(check.totals).items():
        lines.append(f"  engine: {count:,} calls ran on the batched core: {reason}")
    return lines


def entry_record(check: RoutineCheck) -> dict | None:
    """The entry-state runs (retro.analysis.check.entry_runs): null when none ran."""
    if not check.entry_every:
        return None
    t = check.totals
    routine = check.routine
    state = EntryState.of(routine.entry_state, routine.inputs, vary_interrupt=check.start is None)
    first = min(t.entry_first.values(), key=lambda finding: finding.index, default=None)
    return {"cases": t.entry_cases, "every": check.entry_every, "variants": list(VARIANTS),
            "stated": dict(routine.entry_state),
            "varied": [n.upper() for n in state.free_registers] + list(state.free_flags) + ["S", "memory"],
            "changed": t.entry_changed, "needs": entry_needs(check),
            "first": None if first is None else {
                "variant": first.variant, "inputs": inputs_by_name(routine, first.case),
                "outputs": dict(zip(routine.output_names, _plain(first.baseline[0]))), "cycles": first.baseline[1],
                "varied_outputs": None if first.varied[0] is None else dict(zip(routine.output_names,
                                                                                _plain(first.varied[0]))),
                "varied_cycles": first.varied[1] if first.varied[0] is not None else None,
                "stopped": first.varied[1] if first.varied[0] is None else None}}


def draw_record(draw) -> dict | None:
    """How the random part met the `where` domain (retro.routines.cases.DomainDraw); null without one."""
    if draw is None:
        return None
    return {"inside": draw.inside, "share": round(draw.share, 6), "requested": draw.requested, "drawn": draw.drawn,
            "method": draw.method, "ranges": {name: [lo, hi] for name, lo, hi in draw.ranges},
            "candidates": draw.candidates}


def draw_lines(check: RoutineCheck) -> list[str]:
    draw = check.random_draw
    if draw is None or not draw.inside:
        return []
    box = ", ".join(f"{name} {lo}..{hi}" for name, lo, hi in draw.ranges)
    how = (f"sampled from the {draw.candidates:,} combinations of the box {box}" if draw.method == "enumerated" else
           f"drawn in the box {box}" + (f" ({draw.candidates:,} candidates)" if draw.candidates else ""))
    short = "" if draw.drawn == draw.requested else f" of {draw.requested:,} asked for (the draw's budget ran out)"
    return [f"  random cases: {draw.drawn:,}{short} inside the domain (uniform draws keep {100 * draw.share:.2f}%), "
            f"{how}"]


def entry_lines(check: RoutineCheck) -> list[str]:
    record = entry_record(check)
    if record is None:
        return []
    varied = ", ".join(record["varied"][:-1]) + (" and " if len(record["varied"]) > 1 else "") + "untouched memory"
    sample = f"1 case in {record['every']:,}" if record["every"] > 1 else "every case"
    if not record["changed"]:
        return [f"  entry state: {record['cases']:,} cases ({sample}) run again with {varied} all ones and random: "
                "no change"]
    lines = [f"  ENTRY {record['changed']:,} of {record['cases']:,} cases change with {varied} all ones or random:"]
    lines += [f"  ENTRY {need}" for need in record["needs"]]
    first = check.totals.entry_first[record["first"]["variant"]]
    routine = check.routine
    varied_text = (f"stopped ({first.varied[1]})" if first.varied[0] is None else
                   f"{describe_outputs(routine, first.varied[0])} in {first.varied[1]} cycles")
    lines.append(f"  ENTRY e.g. {describe_case(routine, first.case)}: {describe_outputs(routine, first.baseline[0])} "
                 f"in {first.baseline[1]} cycles, with the entry state {first.variant}: {varied_text}")
    return lines


def _plain(values: tuple) -> list:
    return [list(v) if isinstance(v, tuple) else v for v in values]


def format_space(space: int) -> str:
    return f"{space:,}" if space < JSON_EXACT else f"2^{math.log2(space):.1f}"


def format_coverage(check: RoutineCheck) -> str:
    parts = []
    for part in check.parts:
        if part.name == "exhaustive":
            scope = ", ".join(check.routine.exhaustive)
            if part.inside is not None:
                parts.append(f"exhaustive over {scope}: {part.cases:,} of the {part.inside:,} combinations inside "
                             f"the domain (of {part.total:,})"
                             + ("" if part.cases == part.inside else " (sampled; --exhaustive runs all)"))
                continue
            parts.append(f"exhaustive over {scope}: {part.cases:,} of {part.total:,}"
                         + ("" if part.cases == part.total else " (sampled; --exhaustive runs all)"))
        else:
            parts.append(f"{part.name} {part.cases:,}")
    return "; ".join(parts)


def _check_html(check: RoutineCheck) -> str:
    """A check in a notebook: the report `retro check` prints."""
    return options.pre_html(format_check(check))


def format_check(check: RoutineCheck) -> list[str]:
    """One routine's check as the lines `retro check` prints: the headline, what ran, what it cost,
    then every mismatch."""
    return ([_headline(check)] + _run_lines(check) + _measure_lines(check) + _mismatch_lines(check))


def _run_lines(check: RoutineCheck) -> list[str]:
    """What ran: the engine, the spec's notes, the cases and their coverage, the search, the scene's engine."""
    routine = check.routine
    lines = engine_lines(check)
    lines += [f"  note: {note}" for note in routine.notes]
    if check.parts:
        lines.append(f"  cases: {format_coverage(check)}; input space {format_space(check.routine.input_space())}")
    lines += draw_lines(check)
    if routine.coverage:
        lines.append(f"  coverage: {routine.coverage}")
    if check.code_coverage is not None:
        lines.append(f"  {coverage_line(summary(check.code_coverage, routine.program))}")
    elif check.engine == "compiled":
        lines.append("  code: not counted on the compiled engine (--engine batch counts what the cases ran)")
    if _search_line(check):
        lines.append(_search_line(check))
    if check.start is not None and check.engine_reason:
        lines.append(f"  engine with the scene: {_scene_engine(check)}: {check.engine_reason}")
    return lines


def _scene_engine(check: RoutineCheck) -> str:
    if check.engine == "batch":  # stalls per lane as on the scene: the VIC-II's Bad Lines and sprite DMA
        stalled = "each lane stalled as on the scene" if check.totals.stolen_max else "no call stalled on the scene"
        return f"the batched core, {stalled}"
    if check.engine_reason.startswith(FREE_REASON):
        return "Machine (--engine scalar, or too few cases for the batched core to pay)"
    return "Machine"


def _measure_lines(check: RoutineCheck) -> list[str]:
    """What the calls cost and where they fell: cycles, self-modifying code, the budget, the domain,
    the rows, the entry-state runs."""
    t = check.totals
    routine = check.routine
    lines = _cycle_lines(check) if t.cycles_count else []
    if check.static is not None:  # self-modifying code the static analysis followed
        lines += [f"  self-modifying: {note}" for note in check.static.modified]
    if routine.budget is not None:
        lines.append(f"  budget: {routine.budget} cycles: {'broken' if check.budget_violations else 'kept'}")
    lines += [f"  {line}" for line in check.domain_report()[1:]] if routine.domain else []
    if t.outside:
        lines.append(f"  outside the stated domain: {t.outside} cases, {t.outside_wrong} wrong"
                     + (f", e.g. {t.outside_examples[0]}" if t.outside_examples else ""))
    if check.rows is not None:
        lines += rows_lines(routine, check.rows)
    return lines + entry_lines(check)


def _mismatch_lines(check: RoutineCheck) -> list[str]:
    t = check.totals
    lines = [f"  MISMATCH {example}" for example in t.examples]
    lines += [f"  MISMATCH {violation}" for violation in check.bounds_violations]
    lines += [f"  BUDGET {violation}" for violation in check.budget_violations]
    if t.failure is not None:
        lines += _failure_lines(check)
    return lines


def _headline(check: RoutineCheck) -> str:
    t = check.totals
    verdict = "OK" if not check.mismatches else f"{check.mismatches} MISMATCH(ES)"
    stolen = check.start is not None and t.cycles_count  # with a scene the static bounds count the CPU's cycles only
    static = (f"static {check.static.best}-{check.static.worst}{' CPU cycles (stolen cycles not included)' if stolen else ''}"
              f", worst case {'reached' if check.worst_reached else 'not reached'}" if check.static else
              "static bounds unknown" if check.rows is not None and check.rows.static_note else "static analysis off")
    cost = (f"cycles {t.cycles_min}-{t.cycles_max} (mean {check.mean:.2f})" if t.cycles_count
            else "no case inside the domain")
    if stolen:
        cost += f", CPU {t.cpu_min}-{t.cpu_max} without the cycles the chip stole"
    if check.agreement is None:
        checked = f"timing model equal on {t.cases - t.cycle_mismatches - t.run_errors} of {t.cases} calls"
    else:
        a = check.agreement
        checked = (f"{'compiled engine' if check.engine == 'compiled' else 'batched core'}; on {a.engine_cases} of "
                   f"the calls Machine agrees on "
                   f"{a.engine_cases - a.engine_mismatches} and the timing model on "
                   f"{a.cases - a.cycle_mismatches - a.run_errors}")
    note = f" ({check.engine_note})" if check.engine_note else ""
    return f"{check.routine.name}: {t.cases} cases, {verdict}; {cost}, {static}; {checked}{note}"


def _cycle_lines(check: RoutineCheck) -> list[str]:
    """Fastest and slowest inputs (and whether they reach the static bounds), raster lines, and with
    --scene where the calls fall on the beam."""
    t = check.totals
    routine = check.routine
    reach = bounds_reached(check)
    lines = [f"  fastest: {describe_case(routine, t.min_case)}{_reach_text(check, reach, 'best', t.min_case)}",
             f"  slowest: {describe_case(routine, t.max_case)}{_reach_text(check, reach, 'worst', t.max_case)}"]
    raster = format_raster(routine.machine, raster_figures(routine.machine, t.cycles_min, check.mean, t.cycles_max))
    if raster:
        lines.append(f"  raster (CPU never stalled): {raster}")
    scene = scene_raster(check).get("scene")
    if scene and scene["chip"] == "ppu":
        lines += _nes_scene_lines(check, scene)
    elif scene:
        lines.append(f"  on the scene from line {scene['start_line']} cycle {scene['start_cycle']} ({scene['chip']}): "
                     f"{scene['min_lines']:.2f}-{scene['max_lines']:.2f} lines, up to {scene['stolen_max']} cycles "
                     f"stolen; the slowest ends at line {scene['slowest_end_line']} cycle {scene['slowest_end_cycle']}"
                     + (f" {scene['frames_crossed']} frame(s) later" if scene["frames_crossed"] else ""))
    return lines


def _nes_scene_lines(check: RoutineCheck, scene: dict) -> list[str]:
    where = ("the NMI handler's start, " if scene["in_nmi"] else "") + f"scanline {scene['start_line']} dot {scene['start_dot']}"
    v = vblank_record(check)
    return [f"  on the NES scene ({scene['video'].upper()}) from {where}: {scene['min_lines']:.2f}-{scene['max_lines']:.2f} "
            f"scanlines, up to {scene['stolen_max']} cycles of OAM DMA; the slowest returns at scanline "
            f"{scene['slowest_end_line']} dot {scene['slowest_end_dot']}"
            + (f" {scene['frames_crossed']} frame(s) later" if scene["frames_crossed"] else ""),
            f"  vblank budget: {v['budget']} cycles from the start to the pre-render line (rendering starts); the "
            f"fastest call leaves {v['best_left']}, the slowest {v['worst_left']}"
            + (" (it runs into rendering)" if v["worst_left"] < 0 else "")]


def bounds_reached(check: RoutineCheck) -> dict | None:
    """For the static best and worst: the measured extreme, whether a case reached the bound (its
    inputs), and whether the bound is known to be unreachable (true when every input was run and no
    case reached it; null when that is not known). None without static bounds."""
    if check.static is None or not check.totals.cycles_count:
        return None
    t = check.totals
    routine = check.routine
    out = {}
    for key, static, measured, case, reached in (("best", check.static.best, t.cpu_min, t.min_case, check.best_reached),
                                                 ("worst", check.static.worst, t.cpu_max, t.max_case, check.worst_reached)):
        out[key] = {"static": static, "measured": measured, "reached": reached,
                    "inputs": inputs_by_name(routine, case),
                    "found_by_search": check.search is not None and case in check.search.found,
                    "unreachable": False if reached else (True if check.every_input_run else None)}
    return out


def _reach_text(check: RoutineCheck, reach: dict | None, key: str, case: tuple) -> str:
    if reach is None:
        return ""
    bound = reach[key]
    found = " (found by the search)" if bound["found_by_search"] else ""
    if bound["reached"]:
        return f"{found}: reaches the static {key} {bound['static']}"
    verdict = ("it cannot be reached: every input was run" if bound["unreachable"] else
               "whether any input reaches it is not known")
    return f"{found}: {bound['measured']} cycles, static {key} {bound['static']} not reached ({verdict})"


def search_record(check: RoutineCheck) -> dict | None:
    s = check.search
    if s is None:
        return None
    return {"budget": s.budget, "candidates": s.candidates, "cycles": s.cycles, "generations": s.generations,
            "kept": len(s.found),
            "new_branch_directions": s.new_directions, "ended": s.ended}


def _search_line(check: RoutineCheck) -> str | None:
    s = check.search
    if s is None or s.ended == "off":
        return None
    ended = {"budget": f"its budget spent (at most {s.budget:,} candidates and {s.budget * CYCLES_PER_CANDIDATE:,} cycles)", "stale": f"nothing new in {STALE_GENERATIONS} generations",
             "stopped": "a call stopped"}[s.ended]
    return (f"  search: {s.candidates:,} of {s.budget:,} candidates ({s.cycles:,} cycles) in {s.generations} "
            f"generation{'s' if s.generations != 1 else ''}, {len(s.found)} kept ({s.new_directions} new branch "
            f"directions); ended: {ended}")


def _failure_lines(check: RoutineCheck) -> list[str]:
    failure = check.totals.failure
    routine = check.routine
    lines = [f"  first failing case: {describe_case(routine, failure.case)}"]
    if failure.outputs is not None:
        lines.append(f"    routine:   {describe_outputs(routine, failure.outputs)}")
    if failure.expected is not None:
        stated = "the row:  " if failure.kind == "row" else "reference:"
        lines.append(f"    {stated} {describe_outputs(routine, failure.expected)}")
    if failure.message:
        lines.append(f"    {failure.message}")
    lines.append("    trace (address, instruction, cycles, running total):")
    return lines + [f"    {line}" for line in check.trace]


def write_junit(checks: list[RoutineCheck], path: str | Path, *, scene: str | Path | None = None) -> Path:
    """`--junit FILE`: the checks as JUnit XML (retro.analysis.junit), written atomically and never
    over one of the check's inputs."""
    from retro.analysis.junit import junit_xml

    return write_atomic(path, junit_xml(checks, format_check), inputs=input_files(checks, scene))


def input_files(checks: list[RoutineCheck], scene: str | Path | None = None) -> list[Path]:
    """The files the checks read: specs, programs, symbol files, the Python files of their
    references and case functions, the scene."""
    files = [Path(scene)] if scene is not None else []
    for c in checks:
        routine = c.routine
        files += [routine.spec_path, routine.program_file] + ([routine.symbols_file] if routine.symbols_file else [])
        for function in (routine.reference, routine.boundary, routine.sweep, routine.random_generator):
            try:
                source = inspect.getsourcefile(function) if function is not None else None
            except TypeError:  # a builtin or a C function: no file
                source = None
            if source:
                files.append(Path(source))
    return files


# ---- code coverage reports: --listing, --lcov, --html (retro.reports, docs/coverage.md) ----------

def routine_code(check: RoutineCheck) -> RoutineCode:
    """What the coverage reports show of a checked routine: its program's bytes and labels, and its
    source lines from `[program] listing`, else from a symbol file that has them (an ld65 debug file)."""
    from retro.loaders.source_lines import has_line_information, read_source_map
    from retro.reports.annotated import RoutineCode

    routine = check.routine
    program = routine.program
    source_map = routine.source_map
    if source_map is None and routine.symbols_file is not None and has_line_information(routine.symbols_file):
        source_map = read_source_map(routine.symbols_file)
    return RoutineCode(name=routine.name, code=program.code, origin=program.origin, entry=routine.entry_address,
                       cpu=routine.cpu, init=routine.init_address, symbols=dict(program.symbols),
                       program_file=str(routine.program_file), source_map=source_map)


def annotated_checks(checks: list[RoutineCheck]) -> list[Annotated]:
    """Each check's code coverage on its routine's code; a check without it is an error naming it."""
    from retro.reports.annotated import annotate

    missing = [c.routine.name for c in checks if getattr(c, "code_coverage", None) is None]
    if missing:
        raise InputError(f"no code coverage was recorded for {', '.join(missing)} (the compiled engine counts "
                         f"none: use --engine batch), so --listing, --lcov and --html cannot be written")
    return [annotate(routine_code(c), c.code_coverage) for c in checks]


def _source_lines(file: str) -> list[str] | None:
    """A source file's lines for the HTML report (None when it cannot be read: the report names the
    line without its text)."""
    try:
        return read_text(file, "source file").splitlines()
    except InputError:
        return None


def write_coverage_reports(checks: list[RoutineCheck], *, listing: str | Path | None = None,
                           lcov: str | Path | None = None, html: str | Path | None = None,
                           scene: str | Path | None = None) -> list[Path]:
    """`--listing FILE`, `--lcov FILE`, `--html DIR`: written together (with the command's other outputs),
    never over an input: the check's files, the listing or debug file, the source files it names."""
    if listing is None and lcov is None and html is None:
        return []
    from retro.reports.coverage_html import html_pages
    from retro.reports.lcov import lcov_text
    from retro.reports.listing import listing_text

    routines = annotated_checks(checks)
    inputs = input_files(checks, scene)
    for annotated in routines:
        source_map = annotated.code.source_map
        if source_map is not None:
            inputs += [Path(source_map.source)] + [Path(f) for f in {line.file for line in source_map.lines.values()}
                                                   if Path(f).is_file()]
    outputs: dict[Path, str] = {}
    what: dict[Path, str] = {}
    if listing is not None:
        outputs[Path(listing)], what[Path(listing)] = listing_text(routines), "the listing (--listing)"
    if lcov is not None:
        outputs[Path(lcov)], what[Path(lcov)] = lcov_text(routines), "the LCOV file (--lcov)"
    if html is not None:
        pages = html_pages(routines, _source_lines)
        output_folder(html, pages)
        for name, page in pages.items():
            outputs[Path(html) / name], what[Path(html) / name] = page, "the HTML report (--html)"
    return write_all_atomic(outputs, inputs=inputs, what=what)


# The command line: this command's options and how it runs from them.

HELP = ("cross-check 6502 routines (built-in or your own spec) against their references (results and cycles); "
        "exit 1 on any mismatch or broken budget")


def routine_options(p: argparse.ArgumentParser) -> None:
    """What `retro check` and `retro cycles` share: the same run, two views."""
    p.add_argument("routines", nargs="*", metavar="ROUTINE|SPEC.toml",
                   help=f"built-in routine names ({' '.join(builtin_names())}; all when none is given) or routine "
                        "spec files (NAME.toml, docs/specs.md)")
    p.add_argument("--exhaustive", action="store_true",
                   help="the full run: every exhaustive set and sweep, and each spec's full random count (minutes)")
    p.add_argument("--seed", help="seed of the random cases and of random memory (default: the spec's, 0)")
    p.add_argument("--random", metavar="N",
                   help="random cases per routine (default: the spec's count, at most 2,000 without --exhaustive)")
    options.jobs(p, None)
    options.scheduler(p)
    p.add_argument("--scene", metavar="SCENE.toml", help="run every call on a C64 with this VIC-II scene (the CPU "
                   "stalls on Bad Lines and sprite DMA) or on a NES with this NES scene (OAM DMA stalls it; the report "
                   "gives the cycles left before rendering starts); the report gives the lines from the start")
    options.scene_entry(p)
    options.engine(p, f"; scalar is the reference and the timing model checks every call, batch and compiled are "
                      f"checked against Machine on the first {AGREEMENT_PER_PART:,} cases of each part, auto takes "
                      f"batch from {AUTO_BATCH_CASES:,} cases and compiled from {AUTO_COMPILED_CYCLES:,} cycles of planned "
                      f"calls (their count times the geometric mean of the static best and worst cycles)")
    searching = p.add_mutually_exclusive_group()
    searching.add_argument("--search", metavar="N", help="candidate cases the coverage-guided search may run after "
                           f"the planned cases (default: the spec's [cases] search, else {DEFAULT_SEARCH:,}; the "
                           "same cases for a seed on either engine)")
    searching.add_argument("--no-search", dest="search", action="store_const", const="0", help="no search (--search 0)")
    p.add_argument("--json", action="store_true", help="print a JSON list, one object per routine")
    options.quiet(p)


def checks_of(args: argparse.Namespace) -> list[RoutineCheck]:
    """The run `retro check` and `retro cycles` both show, from the options `routine_options` defines."""
    return check(args.routines, exhaustive=args.exhaustive, seed=args.seed, random=args.random, jobs=args.jobs,
                 scene=args.scene, at_line=args.at_line, at_cycle=args.at_cycle, at_dot=args.at_dot,
                 in_nmi=args.in_nmi, engine=args.engine,
                 progress=progress_printer(args.quiet), search=args.search, scheduler=args.scheduler)


def add_options(p: argparse.ArgumentParser) -> None:
    routine_options(p)
    p.add_argument("--junit", metavar="FILE.xml", help="also write the results as JUnit XML for CI: one testcase per "
                                                       "routine, a failure carrying its report")
    p.add_argument("--listing", metavar="FILE", help="write the annotated listing: per instruction its hits, branch "
                                                     "directions and cycles (docs/coverage.md)")
    p.add_argument("--lcov", metavar="FILE", help="write the code coverage as an LCOV tracefile, by source line where "
                                                  "the program has line information, else by address")
    p.add_argument("--html", metavar="DIR", help="write the code coverage as HTML pages into DIR (index.html)")


def main(args: argparse.Namespace) -> int:
    with command_files():  # every file the check writes, all or none
        if args.html is not None:
            output_folder(args.html)  # refused before the run, not after it
        checks = checks_of(args)
        options.show(lines, as_json if args.json else None, checks, indent=1)
        if args.junit:
            write_junit(checks, args.junit, scene=args.scene)
        write_coverage_reports(checks, listing=args.listing, lcov=args.lcov, html=args.html, scene=args.scene)
    return 1 if failed(checks) else 0


# RoutineCheck (retro.analysis.check) knows no text: its notebook display is the report written here.
RoutineCheck._repr_html_ = _check_html
