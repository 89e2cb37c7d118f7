"""The pytest plugin (retro.pytest_plugin): routine specs collected as test items, in a temporary
project run by pytester, with a passing spec, a failing one and a bad one."""

from __future__ import annotations

import shutil
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from retro.cli import main

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "rows_only" / "mulshift.toml"
PLUGIN = "retro.pytest_plugin"


@pytest.fixture
def project(pytester: pytest.Pytester) -> pytest.Pytester:
    """specs/good.toml holds, specs/wrong.toml has a wrong row, specs/broken.toml a bad key; other/ holds
    a copy of the good spec that no pattern names."""
    for folder in ("specs", "other"):
        (pytester.path / folder).mkdir()
        shutil.copy(EXAMPLE.with_suffix(".s"), pytester.path / folder / "mulshift.s")
    text = EXAMPLE.read_text()
    (pytester.path / "specs" / "good.toml").write_text(text)
    (pytester.path / "specs" / "wrong.toml").write_text(text.replace("product = 15,", "product = 16,"))
    (pytester.path / "specs" / "broken.toml").write_text(text.replace("product = 15,", "product = 15, zz = 1,"))
    (pytester.path / "other" / "unnamed.toml").write_text(text)
    return pytester


def _run(project: pytest.Pytester, *args: str) -> pytest.RunResult:
    return project.runpytest("-p", PLUGIN, "-p", "no:cacheprovider", *args)


def test_specs_named_in_the_configuration_are_items_and_fail_with_the_report(project, capsys):
    project.makeini("[pytest]\nretro_specs = specs/*.toml\n")
    junit = project.path / "junit.xml"
    result = _run(project, "-v", f"--junitxml={junit}")
    result.assert_outcomes(passed=1, failed=2)
    result.stdout.fnmatch_lines(["*specs/broken.toml::broken FAILED*", "*specs/good.toml::good PASSED*",
                                 "*specs/wrong.toml::wrong FAILED*"])
    assert "unnamed" not in result.stdout.str()
    # a failing item shows what `retro check` prints for the spec, line for line
    capsys.readouterr()  # what the inner pytest printed
    assert main(["check", str(project.path / "specs" / "wrong.toml")]) == 1
    printed = capsys.readouterr().out
    output = result.stdout.str()
    assert printed.rstrip("\n") in output and len(printed.splitlines()) > 20  # the report and its trace
    assert "ROW rows[1] (two bits): a=3, b=5 -> expected product=16, got product=15" in output
    # a bad spec fails its item with retro's one line, no traceback
    assert "retro check: specs/broken.toml: rows[1].zz: neither an input nor an output" in output
    assert "Traceback" not in output and "InputError" not in output
    # JUnit XML from pytest's own --junitxml: the failure carries the report
    cases = {case.get("name"): case for case in ET.parse(junit).getroot().iter("testcase")}
    assert set(cases) == {"good", "wrong", "broken"}
    assert cases["good"].find("failure") is None
    assert "ROW rows[1] (two bits)" in cases["wrong"].find("failure").text


def test_one_item_per_engine(project):
    project.makeini("[pytest]\nretro_specs = specs/good.toml\nretro_engines = scalar batch\n")
    result = _run(project, "-v")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["*specs/good.toml::good?scalar? PASSED*", "*specs/good.toml::good?batch? PASSED*"])


def test_glob_patterns_in_pyproject_and_the_retro_marker(project):
    project.makepyprojecttoml('[tool.pytest.ini_options]\nretro_specs = ["**/good.toml", "other/*.toml"]\n')
    project.makepyfile(test_plain="def test_plain():\n    pass\n")
    result = _run(project, "-m", "retro", "-v")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["*other/unnamed.toml::unnamed PASSED*", "*specs/good.toml::good PASSED*"])
    assert "test_plain" not in result.stdout.str()


def test_off_unless_configured(project):
    # no retro_specs: the TOML files are left alone, even when named on the command line
    result = _run(project)
    assert result.ret == pytest.ExitCode.NO_TESTS_COLLECTED
    result = _run(project, "specs/good.toml")
    assert result.ret == pytest.ExitCode.USAGE_ERROR  # pytest: "not found" (nothing collects it)


def test_a_spec_named_on_the_command_line_is_collected_once_the_plugin_is_on(project):
    project.makeini("[pytest]\nretro_specs = specs/good.toml\n")
    result = _run(project, "other/unnamed.toml", "-v")
    result.assert_outcomes(passed=1)


def test_a_wrong_engine_is_a_usage_error(project):
    project.makeini("[pytest]\nretro_specs = specs/*.toml\nretro_engines = fast\n")
    result = _run(project)
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    result.stderr.fnmatch_lines(["*retro_engines: 'fast' is not one of auto, scalar, batch*"])


def test_the_plugin_is_installed_by_its_entry_point_and_off_in_this_project():
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert pyproject["project"]["entry-points"]["pytest11"] == {PLUGIN: PLUGIN}
    # this project's own run collects no spec: its configuration names none
    assert "retro_specs" not in pyproject["tool"]["pytest"]["ini_options"]


def test_retro_exhaustive_runs_the_full_check(project):
    # a sweep runs only in the full check: this one leaves a mark when it is called
    (project.path / "specs" / "cases.py").write_text(
        "from pathlib import Path\n\n"
        "def mul(a, b):\n    return a * b\n\n"
        "def sweep():\n    (Path(__file__).parent / 'swept').write_text('yes')\n    return [(3, 5), (255, 255)]\n")
    (project.path / "specs" / "swept.toml").write_text(
        (project.path / "specs" / "good.toml").read_text()
        + '\n[reference]\nfunction = "cases.py:mul"\n\n[cases]\nsweep = "cases.py:sweep"\nrandom = 0\n'
          '\n[cycles]\nloops = { loop = 8 }\n')
    project.makeini("[pytest]\nretro_specs = specs/swept.toml\n")
    _run(project).assert_outcomes(passed=1)
    assert not (project.path / "specs" / "swept").exists()
    _run(project, "--retro-exhaustive").assert_outcomes(passed=1)
    assert (project.path / "specs" / "swept").read_text() == "yes"
