"""The example's own test: `pytest examples/rows_only` (CI runs it with the project's tests).

The spec has rows only: no Python reference. The pytest plugin can collect it without this file
(`retro_specs = ["examples/rows_only/*.toml"]` in a project's pytest configuration, docs/specs.md);
this file shows the same check through retro.testing, on both engines.
"""

from pathlib import Path

import pytest

from retro.testing import assert_routine

SPEC = Path(__file__).parent / "mulshift.toml"


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_every_row_holds(engine):
    report = assert_routine(SPEC, engine=engine)
    assert [o.cycles for o in report.rows.outcomes] == [134, 142, 166, 138]  # 134 + 4 per 1 bit of a
