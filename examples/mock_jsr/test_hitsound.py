"""The example's own test: `pytest examples/mock_jsr` (CI runs it with the project's tests)."""

import tomllib
from pathlib import Path

import pytest

from retro.testing import assert_routine, check, spec_from_dict

HERE = Path(__file__).parent
SPEC = HERE / "hitsound.toml"


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_the_routine_and_its_calls_hold(engine):
    report = assert_routine(SPEC, engine=engine)
    assert report.engine == engine
    # a touch: LDA 3, SEC 2, SBC 3, BCS 2, EOR 2, ADC 2, CMP 2, BCS 2, LDA # 2, JSR 6, the mock's 40,
    # SEC 2, RTS 6 = 74; apart: LDA 3, SEC 2, SBC 3, BCS taken 3, CMP 2, BCS taken 3, CLC 2, RTS 6 = 24
    assert (report.static.best, report.static.worst) == (24, 74)
    assert (report.totals.cycles_min, report.totals.cycles_max) == (24, 74)


def test_a_routine_that_asks_for_the_wrong_sound_fails(tmp_path):
    source = (HERE / "hitsound.s").read_text().replace(".alias hit_sound 2", ".alias hit_sound 3")
    (tmp_path / "hitsound.s").write_text(source)
    (tmp_path / "hitsound_ref.py").write_text((HERE / "hitsound_ref.py").read_text())
    doc = tomllib.loads(SPEC.read_text())
    report = check(spec_from_dict(doc, base=tmp_path, name="hitsound"), engine="batch")
    # every touching pair (|ax - bx| < 8: 15 differences per ax, fewer at the edges) is wrong
    assert report.totals.result_mismatches > 0
    assert all("hit=1, sounds=1, reference hit=0, sounds=1" in e for e in report.totals.examples)
