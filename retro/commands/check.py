"""`retro check`: cross-check routines (built-in names or users' spec files) against their references:
results, cycles (against the timing model) and static bounds; exit 1 on any mismatch."""

from __future__ import annotations

import inspect
import math
from pathlib import Path

from retro.analysis.check import RoutineCheck, SceneStart, inputs_by_name, run_checks
from retro.analysis.check.results import describe_case, describe_outputs
from retro.analysis.junit import junit_xml
from retro.analysis.raster import format_raster, raster_figures
from retro.analysis.row_check import rows_lines, rows_record
from retro.errors import InputError
from retro.fileio import file_option, write_atomic
from retro.numbers import parse_int
from retro.progress import Progress, quiet
from retro.routines import cases as case_sets
from retro.workers import MAX_WORKERS
import argparse
from retro.analysis.check import AGREEMENT_PER_PART, AUTO_BATCH_CASES
from retro.commands import options
from retro.progress import progress_printer
from retro.routines.registry import builtin_names

MAX_RANDOM = 10 ** 9
MAX_JOBS = MAX_WORKERS
MAX_AT_LINE = 1000  # above every chip's line count: the scene's chip gives the exact range
MAX_AT_CYCLE = 100
JSON_EXACT = 1 << 53  # larger whole numbers lose digits in JSON readers that use doubles


def check(routines: list[str] | None = None, *, exhaustive: bool = False, seed: int | str | None = None,
          random: int | str | None = None, jobs: int | str | None = None, scene: str | Path | None = None,
          at_line: int | str | None = None, at_cycle: int | str | None = None, engine: str = "auto",
          progress: Progress = quiet, bounded_product: int = case_sets.BOUNDED_PRODUCT) -> list[RoutineCheck]:
    """Check each routine (all built-ins when none is named). `random`: random cases per routine
    (default: the spec's count, bounded without `exhaustive`); `scene` runs every call on a C64 with
    that VIC-II scene from `at_line`/`at_cycle` (default: the scene's [cpu] start)."""
    return run_checks(
        routines, exhaustive=exhaustive,
        seed=None if seed is None else parse_int(seed, field="--seed", lo=0, hi=2 ** 63 - 1),
        random_count=None if random is None else parse_int(random, field="--random", lo=0, hi=MAX_RANDOM),
        jobs=None if jobs is None else parse_int(jobs, field="--jobs", lo=1, hi=MAX_JOBS),
        progress=progress, start=scene_start(scene, at_line, at_cycle), bounded_product=bounded_product, engine=engine)


def scene_start(scene: str | Path | None, at_line: int | str | None, at_cycle: int | str | None) -> SceneStart | None:
    if file_option(scene, "--scene") is None:
        if at_line is not None or at_cycle is not None:
            raise InputError("--at-line and --at-cycle go with --scene")
        return None
    return SceneStart(str(scene), None if at_line is None else parse_int(at_line, field="--at-line", lo=0, hi=MAX_AT_LINE),
                      None if at_cycle is None else parse_int(at_cycle, field="--at-cycle", lo=1, hi=MAX_AT_CYCLE))


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
            "budget": routine.budget,
            "raster": {**raster_figures(routine.machine, t.cycles_min, check.mean if t.cycles_count else None,
                                        t.cycles_max), **scene_raster(check)}}


def scene_raster(check: RoutineCheck) -> dict:
    """With --scene: the calls on the scene's timeline from the start line ({"scene": {...}}), stalls
    included: lines taken, the most cycles stolen, and where the slowest call ended."""
    start = check.start
    t = check.totals
    if start is None or not t.cycles_count:
        return {}
    video = start.scene.state.video
    per_line = video.cycles_per_line
    last = start.line * per_line + start.cycle - 1 + t.cycles_max - 1
    frames, within = divmod(last, video.frame_cycles)
    end_line, end_cycle = divmod(within, per_line)
    return {"scene": {"chip": video.chip, "start_line": start.line, "start_cycle": start.cycle,
                      "min_lines": round(t.cycles_min / per_line, 3), "mean_lines": round(check.mean / per_line, 3),
                      "max_lines": round(t.cycles_max / per_line, 3), "stolen_max": t.stolen_max,
                      "slowest_end_line": end_line, "slowest_end_cycle": end_cycle + 1, "frames_crossed": frames}}


def check_record(check: RoutineCheck) -> dict:
    """One routine's check as plain data (what `retro check --json` prints)."""
    t = check.totals
    record = {"routine": check.routine.name, "spec": str(check.routine.spec_path), "cpu": check.routine.cpu,
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
              "engine_agreement": None if check.agreement is None else {
                  "cases": check.agreement.engine_cases, "mismatches": check.agreement.engine_mismatches,
                  "timing_model_mismatches": check.agreement.cycle_mismatches},
              "notes": list(check.routine.notes), "first_failure": None, "rows": None}
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


def _plain(values: tuple) -> list:
    return [list(v) if isinstance(v, tuple) else v for v in values]


def format_space(space: int) -> str:
    return f"{space:,}" if space < JSON_EXACT else f"2^{math.log2(space):.1f}"


def format_coverage(check: RoutineCheck) -> str:
    parts = []
    for part in check.parts:
        if part.name == "exhaustive":
            scope = ", ".join(check.routine.exhaustive)
            parts.append(f"exhaustive over {scope}: {part.cases:,} of {part.total:,}"
                         + ("" if part.cases == part.total else " (sampled; --exhaustive runs all)"))
        else:
            parts.append(f"{part.name} {part.cases:,}")
    return "; ".join(parts)


def format_check(check: RoutineCheck) -> list[str]:
    """One routine's check as the lines `retro check` prints."""
    t = check.totals
    routine = check.routine
    lines = [_headline(check)]
    lines += [f"  note: {note}" for note in routine.notes]
    if check.parts:
        lines.append(f"  cases: {format_coverage(check)}; input space {format_space(check.routine.input_space())}")
    if routine.coverage:
        lines.append(f"  coverage: {routine.coverage}")
    if t.cycles_count:
        lines += _cycle_lines(check)
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
    lines += [f"  MISMATCH {example}" for example in t.examples]
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
        checked = (f"batched core; on {a.engine_cases} of the calls Machine agrees on "
                   f"{a.engine_cases - a.engine_mismatches} and the timing model on "
                   f"{a.cases - a.cycle_mismatches - a.run_errors}")
    return f"{check.routine.name}: {t.cases} cases, {verdict}; {cost}, {static}; {checked}"


def _cycle_lines(check: RoutineCheck) -> list[str]:
    """Fastest and slowest inputs, raster lines, and with --scene where the calls fall on the beam."""
    t = check.totals
    routine = check.routine
    lines = [f"  fastest: {describe_case(routine, t.min_case)}", f"  slowest: {describe_case(routine, t.max_case)}"]
    raster = format_raster(routine.machine, raster_figures(routine.machine, t.cycles_min, check.mean, t.cycles_max))
    if raster:
        lines.append(f"  raster (CPU never stalled): {raster}")
    scene = scene_raster(check).get("scene")
    if scene:
        lines.append(f"  on the scene from line {scene['start_line']} cycle {scene['start_cycle']} ({scene['chip']}): "
                     f"{scene['min_lines']:.2f}-{scene['max_lines']:.2f} lines, up to {scene['stolen_max']} cycles "
                     f"stolen; the slowest ends at line {scene['slowest_end_line']} cycle {scene['slowest_end_cycle']}"
                     + (f" {scene['frames_crossed']} frame(s) later" if scene["frames_crossed"] else ""))
    return lines


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
    p.add_argument("--scene", metavar="SCENE.toml", help="run every call on a C64 with this VIC-II scene: the CPU "
                   "stalls on Bad Lines and sprite DMA, and the report gives raster lines from the start line")
    p.add_argument("--at-line", metavar="L", help="with --scene: the raster line each call starts at "
                   "(default: the scene's [cpu] start_line)")
    p.add_argument("--at-cycle", metavar="C", help="with --scene: the cycle in that line (default: the scene's)")
    options.engine(p, f"; scalar is the reference and the timing model checks every call, batch is checked against "
                      f"Machine on the first {AGREEMENT_PER_PART:,} cases of each part, auto takes batch from "
                      f"{AUTO_BATCH_CASES:,} cases")
    p.add_argument("--json", action="store_true", help="print a JSON list, one object per routine")
    options.quiet(p)


def checks_of(args: argparse.Namespace) -> list[RoutineCheck]:
    """The run `retro check` and `retro cycles` both show, from the options `routine_options` defines."""
    return check(args.routines, exhaustive=args.exhaustive, seed=args.seed, random=args.random, jobs=args.jobs,
                 scene=args.scene, at_line=args.at_line, at_cycle=args.at_cycle, engine=args.engine,
                 progress=progress_printer(args.quiet))


def add_options(p: argparse.ArgumentParser) -> None:
    routine_options(p)
    p.add_argument("--junit", metavar="FILE.xml", help="also write the results as JUnit XML for CI: one testcase per "
                                                       "routine, a failure carrying its report")


def main(args: argparse.Namespace) -> int:
    checks = checks_of(args)
    options.show(lines, as_json if args.json else None, checks, indent=1)
    if args.junit:
        write_junit(checks, args.junit, scene=args.scene)
    return 1 if failed(checks) else 0
