"""The example's own test: `pytest examples/stack_args` (CI runs it with the project's tests).

Cycles counted by hand from the datasheet: TSX 2, LDA abs,X 4, SEC 2, SBC abs,X 4, then BCS taken 3
and RTS 6 (first >= second) = 21, or BCS 2, EOR # 2, ADC # 2, RTS 6 = 24. With S at most $FB,
$0104,X stays in page 1: no page is crossed.
"""

from pathlib import Path

from retro.testing import assert_routine

SPEC = Path(__file__).parent / "absdiff.toml"


def test_absdiff_with_its_arguments_on_the_stack():
    report = assert_routine(SPEC)
    assert (report.totals.cycles_min, report.totals.cycles_max) == (21, 24)
