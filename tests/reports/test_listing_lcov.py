"""The annotated listing and the LCOV file of the hand-worked routine (handworked.py): every figure
expected here was counted by hand, never taken from the code under test."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest
from handworked import (
    ACME_LINE,
    ADDRESSES,
    DATA,
    ENTRY,
    EXPECTED_LISTING_ROWS,
    HAND,
    ROWS,
    SOURCE_LINE,
    expected_lcov,
    machine_coverage,
)

from retro.analysis.coverage_model import CodeCoverage
from retro.loaders import load_program
from retro.loaders.source_lines import parse_source_map, read_source_map
from retro.reports.annotated import RoutineCode, annotate, labels_by_address
from retro.reports.lcov import lcov_text
from retro.reports.listing import HEADER, listing_lines
from retro.errors import InputError

PRG = DATA / "sumto.prg"


def program():
    return load_program(PRG, symbols=DATA / "sumto.dbg")


def code(source_map=None, name="sumto") -> RoutineCode:
    p = program()
    return RoutineCode(name=name, code=p.code, origin=p.origin, entry=ENTRY, symbols=dict(p.symbols),
                       program_file=str(PRG), source_map=source_map)


def test_the_hand_count_is_what_the_machine_runs():
    """The hand count (handworked.HAND) against the scalar Machine's traces of the three rows: the
    figures the report tests expect are the routine's real behaviour."""
    found = machine_coverage(program(), ENTRY, [{"x": x} for x in ROWS], ADDRESSES)
    assert found == HAND


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_the_engines_fill_the_hand_count(engine):
    """`retro check sumto.toml` records the hand-counted coverage on either engine (once the engines
    collect it)."""
    from retro.commands.check import check
    [result] = check([str(DATA / "sumto.toml")], engine=engine)
    if getattr(result, "code_coverage", None) is None:
        pytest.skip("RoutineCheck.code_coverage is not filled yet (the engines' collection is another branch)")
    assert result.code_coverage == HAND


def test_listing_of_the_hand_worked_routine():
    lines = listing_lines(annotate(code(read_source_map(DATA / "sumto.dbg")), HAND))
    assert lines[0] == f"sumto: entry $C000 ({PRG})"
    assert lines[1] == "  instructions: 9 of 11 run (81.8%); branch directions: 5 of 6 (83.3%)"
    assert lines[2] == "  worst case: 51 cycles over 19 instructions (marked >)"
    table = lines[lines.index(HEADER) + 1:]
    assert [line.split() for line in table] == EXPECTED_LISTING_ROWS


def test_listing_columns_line_up_under_the_header():
    """Each figure ends where its header ends (right-aligned columns)."""
    lines = listing_lines(annotate(code(), HAND))
    row = next(line for line in lines if "$C00A" in line)
    for title, value in (("hits", "4"), ("taken", "0!"), ("not taken", "4"), ("min", "2"), ("max", "2")):
        end = HEADER.index(title) + len(title)
        assert row[end - len(value):end] == value, title
    assert lines[lines.index(HEADER) + 1].index("sumto:") == HEADER.index("instruction")


def test_listing_marks_a_branch_that_never_ran_and_a_gap():
    """A branch no case reached shows '-' both ways; bytes between instructions are named."""
    coverage = CodeCoverage(executed={0xC000: 1, 0xC004: 0}, taken={0xC004: 0}, not_taken={0xC004: 0},
                            cycles_min={0xC000: 2}, cycles_max={0xC000: 2})
    lines = listing_lines(annotate(code(), coverage))
    branch = next(line for line in lines if "$C004" in line)
    assert branch.split()[4:8] == ["$C00F", "#####", "-", "-"]
    assert "  $C002-$C003: 2 bytes no path from the entry runs" in lines


def test_labels_keep_one_spelling_per_name():
    assert labels_by_address({"fill::loop": 1, "fill.loop": 1, "loop": 1, "start": 2, "begin": 2}) == {
        1: ("fill::loop",), 2: ("begin", "start")}


# ---- LCOV -----------------------------------------------------------------------------------------

def test_lcov_by_ca65_source_lines():
    text = lcov_text([annotate(code(read_source_map(DATA / "sumto.dbg")), HAND)])
    assert text == expected_lcov(str(DATA / "sumto.s"), SOURCE_LINE)


def test_lcov_by_acme_report_lines():
    text = lcov_text([annotate(code(read_source_map(DATA / "sumto_acme.lst")), HAND)])
    assert text == expected_lcov(str(DATA / "sumto_acme.asm"), ACME_LINE)


def test_lcov_by_address_without_line_information():
    text = lcov_text([annotate(code(name="sum to!"), HAND)])
    expected = expected_lcov(f"{PRG}.addresses", {a: a for a in ADDRESSES}, name="sum_to_")
    assert text == expected  # names made of letters, digits and _ (a comma would end genhtml's function name)


def test_source_lines_of_a_macro_and_an_include():
    """ca65: a macro's bytes count on the line that calls it; ACME: a line's bytes past the 8 its
    report shows (`...`) run to the next line's address."""
    dbg = "\n".join([
        "version\tmajor=2,minor=0", 'file\tid=0,name="m.s",size=1,mtime=0x0,mod=0', 'file\tid=1,name="inc.s",size=1,mtime=0x0,mod=0',
        "seg\tid=0,name=\"CODE\",start=0x00C000,size=0x000A,addrsize=absolute,type=rw",
        "span\tid=0,seg=0,start=0,size=2", "span\tid=1,seg=0,start=2,size=1", "span\tid=2,seg=0,start=3,size=2",
        "span\tid=3,seg=0,start=2,size=3", "span\tid=4,seg=0,start=5,size=1",
        "line\tid=0,file=0,line=6,span=0", "line\tid=1,file=0,line=2,type=2,count=1,span=1",
        "line\tid=2,file=0,line=3,type=2,count=1,span=2", "line\tid=3,file=0,line=7,span=3", "line\tid=4,file=1,line=1,span=4"])
    lines = parse_source_map(dbg, "m.dbg").lines
    assert {a: (l.file, l.line) for a, l in lines.items()} == {
        0xC000: ("m.s", 6), 0xC001: ("m.s", 6), 0xC002: ("m.s", 7), 0xC003: ("m.s", 7), 0xC004: ("m.s", 7),
        0xC005: ("inc.s", 1)}
    report = "\n".join(["; ******** Source: a.asm", "     7  c000 a901               start   lda #1",
                        "     8  c002 0102030405060708...data    !byte 1,2,3,4,5,6,7,8,9,10",
                        "", "; ******** Source: b.asm", "     1  c00c aa                         tax"])
    lines = parse_source_map(report, "a.lst").lines
    assert lines[0xC000].line == 7 and lines[0xC00B] == lines[0xC002] and lines[0xC00B].line == 8
    assert (lines[0xC00C].file, lines[0xC00C].line) == ("b.asm", 1)


@pytest.mark.parametrize("text, message", [
    ("; 64tass Turbo Assembler Macro V1.58 listing file\n", "gives no line numbers for the main file"),
    ("hello\n", "not a source map retro reads"),
    ("version\tmajor=2,minor=0\nline\tid=0,file=3,line=1,span=0\n", "file 3 is not defined"),
    ("; ******** Source: a.asm\n     1  1c000 a9\n", r"above \$FFFF"),
])
def test_bad_source_maps_are_one_line_errors(text, message):
    with pytest.raises(InputError, match=message):
        parse_source_map(text, "x.lst")


# ---- genhtml accepts the file -----------------------------------------------------------------------

def _genhtml() -> str:
    found = shutil.which("genhtml")
    if found is None:
        if os.environ.get("CI") == "true":
            pytest.fail("genhtml is missing on CI: .ci/run installs Debian's lcov package")
        pytest.skip("genhtml is not installed (apt-get install lcov)")
    return found


def test_genhtml_accepts_the_lcov_files(tmp_path):
    genhtml = _genhtml()
    by_line = tmp_path / "lines.info"
    by_line.write_text(lcov_text([annotate(code(read_source_map(DATA / "sumto.dbg")), HAND)]))
    by_address = tmp_path / "addresses.info"
    by_address.write_text(lcov_text([annotate(code(), HAND)]))
    for info, extra in ((by_line, []), (by_address, ["--no-source"])):
        out = tmp_path / info.stem
        done = subprocess.run([genhtml, "--branch-coverage", "--quiet", "-o", str(out), *extra, str(info)],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        index = (out / "index.html").read_text()
        assert "81.8&nbsp;%" in index  # 9 of 11 lines
        assert "83.3&nbsp;%" in index  # 5 of 6 branches
