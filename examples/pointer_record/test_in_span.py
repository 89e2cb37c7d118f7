"""The example's own test: `pytest examples/pointer_record` (CI runs it with the project's tests).

Cycles counted by hand from the datasheet: LDY # 2, SEC 2, SBC (zp),Y 5, then BCC taken 3, SEC 2,
RTS 6 (left of the span) = 20; or BCC 2, INY 2, CMP (zp),Y 5, RTS 6 = 24, one more when the
record's second byte lies across a page from the pointer (span = $xxFF) = 25.
"""

from pathlib import Path

from retro.testing import assert_routine

SPEC = Path(__file__).parent / "in_span.toml"


def test_in_span_through_its_pointer():
    report = assert_routine(SPEC)
    assert (report.totals.cycles_min, report.totals.cycles_max) == (20, 25)
