"""`retro check --junit FILE`: the checks as JUnit XML, for CI systems that read test results.

The layout follows the JUnit XML schema that CI servers read (the Ant JUnit task's format, as
written down in the Windy Road JUnit.xsd, and Jenkins' junit-10.xsd):

    <testsuites name tests failures errors time>
      <testsuite name tests failures errors time timestamp hostname id package>
        <properties/>
        <testcase name classname time>           one per routine
          <failure message type>report</failure> when the check found anything wrong
        </testcase>
        <system-out>every routine's report</system-out>
        <system-err/>
      </testsuite>
    </testsuites>

A testcase's name is the routine's, its classname the spec's path with dots (`examples.boxhit.boxhit`,
so a CI server groups the specs of one folder; `retro.builtin.NAME` for a built-in routine), its
time the check's wall time in seconds. A failure carries the text `retro check` prints for the
routine; its message is the report's first line. Errors stay 0: a bad spec stops `retro check`
(exit 2) before any file is written.
"""

from __future__ import annotations

import re
import socket
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path

from retro.analysis.check import RoutineCheck
from retro.paths import ASM_DIR

SUITE_NAME = "retro check"
FAILURE_TYPE = "retro.mismatch"
# XML 1.0 allows tab, newline, carriage return and the characters from space up (surrogates and
# U+FFFE/U+FFFF excepted); anything else in a report (a terminal escape in a name) is shown escaped
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def xml_text(text: str) -> str:
    return _NOT_XML.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


def classname(check: RoutineCheck) -> str:
    """The spec's path (relative to the working folder when under it) with dots for separators."""
    path = Path(check.routine.spec_path)
    if path.parent.resolve() == ASM_DIR.resolve():
        return f"retro.builtin.{path.stem}"
    try:
        path = path.resolve().relative_to(Path.cwd().resolve())
    except (ValueError, OSError):
        pass
    parts = [part for part in path.with_suffix("").parts if part.strip("/\\")]
    return ".".join(part.replace(".", "_") for part in parts) or check.routine.name


def junit_xml(checks: list[RoutineCheck], report_of: Callable[[RoutineCheck], list[str]], *,
              timestamp: float | None = None, hostname: str | None = None) -> str:
    """The checks as one JUnit XML document (UTF-8 text with its declaration); `report_of` gives a
    check's text report (retro/commands/check.py: format_check, which lives above this layer)."""
    failures = sum(1 for c in checks if c.mismatches)
    seconds = sum(c.seconds for c in checks)
    counts = {"tests": str(len(checks)), "failures": str(failures), "errors": "0", "time": f"{seconds:.3f}"}
    root = ET.Element("testsuites", {"name": SUITE_NAME, **counts})
    when = time.strftime("%Y-%m-%dT%H:%M:%S", time.localtime(time.time() if timestamp is None else timestamp))
    suite = ET.SubElement(root, "testsuite", {"name": SUITE_NAME, **counts, "timestamp": when,
                                              "hostname": hostname or _hostname(), "id": "0", "package": "retro"})
    ET.SubElement(suite, "properties")
    reports = []
    for check in checks:
        report = report_of(check)
        reports.extend(report)
        case = ET.SubElement(suite, "testcase", {"name": xml_text(check.routine.name),
                                                 "classname": xml_text(classname(check)), "time": f"{check.seconds:.3f}"})
        if check.mismatches:
            failure = ET.SubElement(case, "failure", {"message": xml_text(report[0]), "type": FAILURE_TYPE})
            failure.text = xml_text("\n".join(report))
    ET.SubElement(suite, "system-out").text = xml_text("\n".join(reports))
    ET.SubElement(suite, "system-err")
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _hostname() -> str:
    try:
        return socket.gethostname() or "localhost"
    except OSError:
        return "localhost"
