"""The example's own test: `pytest examples/object_table` (CI runs it with the project's tests).

Cycles counted by hand from the datasheet: the x test is LDA abs,X 4, SEC 2, SBC zp 3, CLC 2,
ADC # 2, CMP # 2 = 15; then BCS taken 3, CLC 2, RTS 6: a miss along x costs 26. Past it (BCS not
taken 2: 17 so far) the y test is another 15: BCS not taken 2, SEC 2, RTS 6 makes a hit 42; BCS
taken 3, CLC 2, RTS 6 makes a miss along y 43.
obj_x and obj_y lie within one page: no page is crossed.
"""

from pathlib import Path

from retro.testing import assert_routine

SPEC = Path(__file__).parent / "hit_slot.toml"


def test_hit_slot_over_every_slot():
    report = assert_routine(SPEC)
    assert (report.totals.cycles_min, report.totals.cycles_max) == (26, 43)
