"""The example's own tests: run with `pytest examples/65c02_boxhit`."""

import tomllib
from pathlib import Path

import pytest

from retro.commands.check import cycle_figures
from retro.errors import InputError
from retro.testing import RoutineFailed, assert_routine, check, spec_from_dict

HERE = Path(__file__).parent
SPEC = HERE / "hit65.toml"


def test_hit65_matches_its_reference_on_the_65c02_with_no_raster_figures():
    report = assert_routine(SPEC, random=300)
    assert report.routine.cpu == "65c02" and report.routine.machine == "none"
    assert report.totals.cases > 65_536
    assert report.static.worst <= 120
    assert report.size.code_bytes == 0x1042 - 0x1000  # init and hit65, decoded as 65C02 code
    assert cycle_figures(report)["raster"] == {}  # a bare CPU: no C64 or NES lines


def _spec(**program) -> dict:
    doc = tomllib.loads(SPEC.read_text())
    doc["program"].update(program)
    doc["cases"] = {"random": 200, "seed": 2, "where": doc["cases"]["where"]}
    return doc


def test_on_an_nmos_cpu_the_same_bytes_fail():
    """The (zp) opcodes are JAMs on the 6510: the static analysis names the first one, and without it
    the run stops on it."""
    with pytest.raises(InputError, match=r"\$100B: opcode \$B2 is not an instruction the 6510 runs"):
        check(spec_from_dict(_spec(cpu="6510"), base=HERE))
    doc = _spec(cpu="6510")
    doc["cycles"]["static"] = False
    with pytest.raises(RoutineFailed, match=r"JAM \(opcode \$B2\) at \$100B"):
        assert_routine(spec_from_dict(doc, base=HERE))


def test_naming_a_machine_brings_its_raster_figures_only_with_its_cpu():
    report = check(spec_from_dict(_spec(machine="none"), base=HERE))
    assert report.routine.machine == "none"
    with pytest.raises(InputError, match=r"program\.machine: the C64 has a 6510, not the 65C02"):
        spec_from_dict(_spec(machine="c64"), base=HERE)
