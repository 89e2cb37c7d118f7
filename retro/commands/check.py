"""`retro check`: cross-check routines (built-in names or users' spec files) against their references:
results, cycles (against the timing model) and static bounds; exit 1 on any mismatch."""

from __future__ import annotations

import inspect
from pathlib import Path

from retro.analysis.check import RoutineCheck, SceneStart, check_record, format_check, run_checks
from retro.analysis.junit import junit_xml
from retro.errors import InputError
from retro.fileio import file_option, write_atomic
from retro.numbers import parse_int
from retro.progress import Progress, quiet
from retro.routines import cases as case_sets
from retro.workers import MAX_WORKERS

MAX_RANDOM = 10 ** 9
MAX_JOBS = MAX_WORKERS
MAX_AT_LINE = 1000  # above every chip's line count: the scene's chip gives the exact range
MAX_AT_CYCLE = 100


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


def write_junit(checks: list[RoutineCheck], path: str | Path, *, scene: str | Path | None = None) -> Path:
    """`--junit FILE`: the checks as JUnit XML (retro.analysis.junit), written atomically and never
    over one of the check's inputs."""
    return write_atomic(path, junit_xml(checks), inputs=input_files(checks, scene))


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
