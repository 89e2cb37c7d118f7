"""The example's own test: `pytest examples/irq_handler` (CI runs it with the project's tests)."""

import tomllib
from pathlib import Path

import pytest

from retro.testing import assert_routine, check, spec_from_dict

HERE = Path(__file__).parent
SPEC = HERE / "raster_irq.toml"


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_the_handler_holds(engine):
    report = assert_routine(SPEC, engine=engine)
    assert report.engine == engine and not report.engine_note
    # the interrupt sequence 7, LDA # 2, STA abs 4, INC abs 6, LDA abs 4, AND # 2, TAX 2, LDA abs,X 4
    # (the AND leaves X small enough that the table read never crosses its page: the value analysis
    # knows it), STA abs 4, JMP 3 (the exit: counted, $EA31 not run)
    assert (report.static.best, report.static.worst) == (38, 38)
    assert report.totals.cycles_min == report.totals.cycles_max == 38


def test_a_handler_that_forgets_the_acknowledgement_fails(tmp_path):
    source = (HERE / "raster_irq.s").read_text().replace("        sta vic_irq ", "        nop\n        nop\n;")
    (tmp_path / "raster_irq.s").write_text(source)
    (tmp_path / "raster_irq_ref.py").write_text((HERE / "raster_irq_ref.py").read_text())
    report = check(spec_from_dict(tomllib.loads(SPEC.read_text()), base=tmp_path, name="raster_irq"))
    assert report.totals.result_mismatches == report.totals.cases
    assert "acks=[00], ack_writes=0" in report.totals.examples[0]
