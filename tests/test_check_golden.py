"""The JSON of `retro check` / `retro cycles` equals what main printed before the refactor of issue 21
(recorded at d1bc2f2: 64be42f plus the work merged before the refactor), for every built-in routine,
every example and test spec, each engine, with a VIC-II scene and for checks that fail in each way. The golden files were recorded by
tests/golden/make_check_golden.py (which says how they are normalised: only the checkout's absolute
path is replaced; the check's JSON carries no timings)."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

_SCRIPT = Path(__file__).parent / "golden" / "make_check_golden.py"
_spec = importlib.util.spec_from_file_location("make_check_golden", _SCRIPT)
golden = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(golden)

CASES = golden.cases()

# Keys that features after the recording added to a routine's JSON (a key missing from the recording
# fails the test unless it is named here; every recorded key must still be there with its value).
ADDED_KEYS: set[str] = {"code_coverage", "search", "bounds_reached", "engine_note", "entry_dependence", "random_draw",
                        "engine_reason", "compile_seconds", "compiled_fallbacks", "table_blocks", "cpu_min", "cpu_max",
                        "static_modified", "vblank"}


def test_every_case_has_a_golden_file_and_no_file_is_stale():
    recorded = {p.stem for p in golden.GOLDEN.glob("*.json")}
    assert recorded == set(CASES)


@pytest.mark.parametrize("name", sorted(CASES))
def test_check_json_is_unchanged(name):
    expected = json.loads(golden.golden_path(name).read_text())
    got = golden.run(CASES[name])
    assert got["args"] == expected["args"]
    assert got["exit"] == expected["exit"]
    assert len(got["json"]) == len(expected["json"])
    for mine, theirs in zip(got["json"], expected["json"]):
        differing = sorted(k for k in (set(mine) - ADDED_KEYS) | set(theirs) if mine.get(k) != theirs.get(k))
        assert not differing, f"{theirs.get('routine')}: {differing} differ"
