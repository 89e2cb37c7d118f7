"""Check your own routine from pytest: `check` runs a spec (a file, or one built in Python) and
returns the report; `assert_routine` fails the test with the whole report when anything is wrong.

    from retro.testing import assert_routine

    def test_boxhit():
        report = assert_routine("boxhit.toml")             # results, cycles, static bounds, budget
        assert report.totals.cycles_max <= 60

    def test_boxhit_built_in_python():
        spec = spec_from_dict({"program": {...}, "inputs": {...}, ...}, base=Path(__file__).parent)
        assert_routine(spec, exhaustive=True)

The keys of a spec dict are those of the TOML file (docs/specs.md); relative paths in it are
resolved against `base`. docs/specs.md shows a complete example (examples/boxhit/).
"""

from __future__ import annotations

from pathlib import Path

from retro.analysis.check import RoutineCheck, check_routine
from retro.commands.check import format_check
from retro.routines.spec import Routine, parse_spec

__all__ = ["RoutineCheck", "RoutineFailed", "assert_routine", "check", "report_text", "spec_from_dict"]


class RoutineFailed(AssertionError):
    """A routine check that found mismatches or a broken budget; the message is the whole report."""

    def __init__(self, report: RoutineCheck) -> None:
        super().__init__(report_text(report))
        self.report = report


def spec_from_dict(doc: dict, base: str | Path = ".", name: str = "spec") -> Routine:
    """A routine spec given as a dict (the TOML file's structure); paths resolve against `base`."""
    return parse_spec(doc, Path(base).resolve() / f"{name}.toml", shown=f"{name} (built in Python)")


def check(spec: str | Path | Routine, *, exhaustive: bool = False, random: int | None = None,
          seed: int | None = None, jobs: int = 1, engine: str = "auto", search_budget: int | None = None) -> RoutineCheck:
    """Run a routine's check; the report is plain data (see retro.analysis.check.RoutineCheck).
    `engine`: "scalar", "batch" or "auto" (the default), as `retro check --engine`; `search_budget`:
    candidates of the coverage-guided search, as `--search` (None: the spec's or the default)."""
    return check_routine(spec if isinstance(spec, Routine) else str(spec), exhaustive=exhaustive, seed=seed,
                         random_count=random, jobs=jobs, engine=engine, search_budget=search_budget)


def assert_routine(spec: str | Path | Routine, **options) -> RoutineCheck:
    """`check`, failing (RoutineFailed, an AssertionError) with the report when anything is wrong."""
    report = check(spec, **options)
    if report.mismatches:
        raise RoutineFailed(report)
    return report


def report_text(report: RoutineCheck) -> str:
    return "\n".join(format_check(report))
