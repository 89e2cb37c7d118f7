"""`retro check --junit FILE`: JUnit XML for CI systems without pytest (retro.analysis.junit).

The document is held against the rules of the JUnit XML schema CI servers read, written down here
from the Windy Road JUnit.xsd (the Ant JUnit task's format) and Jenkins' junit-10.xsd: testsuites
holding testsuite elements, each with name, tests, failures, errors, time, timestamp (ISO 8601
without a zone), hostname, id and package, its children in the order properties, testcase...,
system-out, system-err; a testcase with name, classname and time (seconds, a decimal), holding at
most one failure or error, which has a message and a type; the counts equal what the elements hold.
"""

from __future__ import annotations

import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from retro.cli import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "rows_only" / "mulshift.toml"
TIMESTAMP = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d$")
DECIMAL = re.compile(r"^\d+(\.\d+)?$")


def assert_junit_schema(root: ET.Element) -> None:
    assert root.tag == "testsuites"
    totals = {"tests": 0, "failures": 0, "errors": 0}
    for suite in root:
        assert suite.tag == "testsuite"
        for attribute in ("name", "tests", "failures", "errors", "time", "timestamp", "hostname", "id", "package"):
            assert suite.get(attribute), attribute
        assert TIMESTAMP.match(suite.get("timestamp")) and DECIMAL.match(suite.get("time"))
        tags = [child.tag for child in suite]
        assert tags[0] == "properties" and tags[-2:] == ["system-out", "system-err"]
        cases = list(suite)[1:-2]
        assert all(case.tag == "testcase" for case in cases)
        counts = {"tests": len(cases), "failures": 0, "errors": 0}
        for case in cases:
            assert case.get("name") and case.get("classname") and DECIMAL.match(case.get("time"))
            outcome = list(case)
            assert len(outcome) <= 1 and all(child.tag in ("failure", "error") for child in outcome)
            for child in outcome:
                assert child.get("message") and child.get("type")
                counts["failures" if child.tag == "failure" else "errors"] += 1
        for key, value in counts.items():
            assert int(suite.get(key)) == value, key
            totals[key] += value
    for key, value in totals.items():
        assert int(root.get(key)) == value, key


def _specs(tmp_path: Path) -> tuple[Path, Path]:
    shutil.copy(EXAMPLE.with_suffix(".s"), tmp_path / "mulshift.s")
    good = tmp_path / "mulshift.toml"
    good.write_text(EXAMPLE.read_text())
    bad = tmp_path / "wrong.toml"
    bad.write_text(EXAMPLE.read_text().replace('product = 15,', 'product = 16,'))
    return good, bad


def test_one_testcase_per_routine_and_a_failure_carrying_the_report(tmp_path, capsys):
    good, bad = _specs(tmp_path)
    out = tmp_path / "results.xml"
    assert main(["check", str(good), str(bad), "--junit", str(out)]) == 1
    capsys.readouterr()
    root = ET.parse(out).getroot()
    assert_junit_schema(root)
    (suite,) = root
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("2", "1", "0")
    passing, failing = suite.findall("testcase")
    assert (passing.get("name"), failing.get("name")) == ("mulshift", "wrong")
    assert list(passing) == []
    (failure,) = list(failing)
    assert failure.tag == "failure"
    # the failure carries what `retro check` prints for that routine, its first line as the message
    main(["check", str(bad)])
    printed = capsys.readouterr().out
    assert failure.text == printed.rstrip("\n")
    assert failure.get("message") == printed.splitlines()[0]
    assert "ROW rows[1] (two bits): a=3, b=5 -> expected product=16, got product=15" in failure.text
    assert "mulshift: 4 cases, OK" in suite.find("system-out").text


def test_classname_is_the_spec_path_with_dots(tmp_path, capsys, monkeypatch):
    good, _ = _specs(tmp_path)
    monkeypatch.chdir(tmp_path.parent)
    out = tmp_path / "results.xml"
    assert main(["check", str(good), "aabb8", "--random", "10", "--junit", str(out), "--quiet"]) == 0
    capsys.readouterr()
    first, builtin = ET.parse(out).getroot().iter("testcase")
    assert first.get("classname") == f"{tmp_path.name}.mulshift"
    assert builtin.get("classname") == "retro.builtin.aabb8"


@pytest.mark.parametrize("target", ["mulshift.toml", "mulshift.s"])
def test_never_written_over_an_input(tmp_path, capsys, target):
    good, _ = _specs(tmp_path)
    before = (tmp_path / target).read_bytes()
    assert main(["check", str(good), "--junit", str(tmp_path / target)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is an input of this command" in err and "refusing to write over it" in err
    assert (tmp_path / target).read_bytes() == before


def test_written_atomically_over_an_old_report(tmp_path, capsys):
    good, _ = _specs(tmp_path)
    out = tmp_path / "results.xml"
    out.write_text("old")
    assert main(["check", str(good), "--junit", str(out)]) == 0
    assert_junit_schema(ET.parse(out).getroot())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mulshift.s", "mulshift.toml", "results.xml", "wrong.toml"]


def test_control_characters_in_a_name_stay_valid_xml(tmp_path, capsys):
    good, _ = _specs(tmp_path)
    odd = tmp_path / "odd.toml"
    odd.write_text('name = "mul\\u001b[31m"\n' + good.read_text())
    out = tmp_path / "results.xml"
    assert main(["check", str(odd), "--junit", str(out)]) == 0
    (case,) = ET.parse(out).getroot().iter("testcase")
    assert case.get("name") == "mul\\x1b[31m"
