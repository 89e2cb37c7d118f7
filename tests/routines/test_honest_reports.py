"""Honest reports (issue 22, part 6): a user routine's table bytes are the `[memory]` blocks it read
(and the report says which), pointers and S print as $hex, `--json` gives the spec's path as the user
gave it, and an input's `size` without `values` is refused as ambiguous (tests/routines/
test_conventions.py has that error's line)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from retro.analysis.check.results import describe_case
from retro.cli import main
from retro.routines.spec import load_spec
from retro.testing import check

ROOT = Path(__file__).resolve().parents[2]

# a * b by quarter squares: floor((a+b)^2/4) - floor((a-b)^2/4), two 512-byte tables read with abs,X;
# a third block the routine never reads
MUL = """\
        .org $c000
        .alias a $fb
        .alias b $fc
        .alias sqr_lo $2000
        .alias sqr_hi $2200
mul:    lda a
        clc
        adc b
        tax
        bcc +
        lda sqr_lo+256,x
        sta lo
        lda sqr_hi+256,x
        sta hi
        jmp ++
*       lda sqr_lo,x
        sta lo
        lda sqr_hi,x
        sta hi
*       lda a
        sec
        sbc b
        bcs +
        eor #$ff
        adc #1
*       tax
        lda lo
        sec
        sbc sqr_lo,x
        sta lo
        lda hi
        sbc sqr_hi,x
        sta hi
        rts
lo:     .byte 0
hi:     .byte 0
"""
REFS = """\
def squares_lo():
    return [((n * n) // 4) & 0xFF for n in range(512)]

def squares_hi():
    return [((n * n) // 4) >> 8 for n in range(512)]

def mul(a, b):
    return a * b
"""
SPEC = """\
[program]
file = "mul.s"
entry = "mul"

[inputs]
a = "$fb"
b = "$fc"

[outputs]
product = { at = "lo", size = 2 }

[memory]
sqr_lo = { at = "$2000", generator = "refs.py:squares_lo" }
sqr_hi = { at = "$2200", generator = "refs.py:squares_hi" }
unused = { at = "$3000", size = 100, fill = 0 }

[reference]
function = "refs.py:mul"

[cases]
random = 3000

[entry]
d = 0        # its ADC needs binary mode
"""


@pytest.fixture
def mul_spec(tmp_path) -> Path:
    (tmp_path / "mul.s").write_text(MUL)
    (tmp_path / "refs.py").write_text(REFS)
    (tmp_path / "mul.toml").write_text(SPEC)
    return tmp_path / "mul.toml"


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_table_bytes_are_the_memory_blocks_the_routine_read(mul_spec, engine):
    report = check(mul_spec, engine=engine)
    assert report.mismatches == 0
    assert report.size.table_bytes == 2 * 512  # not the 100 bytes of `unused`, which it never reads
    assert report.size.table_blocks == (("sqr_lo", 512), ("sqr_hi", 512))


def test_the_cost_table_says_which_blocks(mul_spec, capsys, monkeypatch):
    monkeypatch.chdir(mul_spec.parent)
    assert main(["cycles", "mul.toml", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "tables of mul: the [memory] blocks it read: sqr_lo (512 bytes), sqr_hi (512 bytes)" in out
    assert main(["cycles", "mul.toml", "--quiet", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)[0]
    assert (row["table_bytes"], row["table_blocks"]) == (1024, {"sqr_lo": 512, "sqr_hi": 512})


def test_a_block_read_only_through_a_pointer_counts(tmp_path):
    """(zp),Y reads: the pointer is set by the routine itself, so no operand names the block."""
    (tmp_path / "p.s").write_text("""\
        .org $c000
peek:   lda #$00
        sta $fd
        lda #$40
        sta $fe
        lda ($fd),y
        rts
""")
    (tmp_path / "refs.py").write_text("def same(y):\n    return y ^ 0x55\n\n"
                                      "def table():\n    return [n ^ 0x55 for n in range(256)]\n")
    (tmp_path / "p.toml").write_text("""\
[program]
file = "p.s"
entry = "peek"
[inputs]
y = "Y"
[outputs]
a = "A"
[memory]
data = { at = "$4000", generator = "refs.py:table" }
[reference]
function = "refs.py:same"
[cases]
exhaustive = ["y"]
random = 0
""")
    report = check(tmp_path / "p.toml", engine="scalar")
    assert report.mismatches == 0 and report.size.table_blocks == (("data", 256),)


def test_json_gives_the_spec_path_as_given(mul_spec, capsys, monkeypatch):
    monkeypatch.chdir(mul_spec.parent.parent)
    given = os.path.join(mul_spec.parent.name, "mul.toml")
    assert main(["check", given, "--quiet", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)[0]["spec"] == given


def test_pointers_and_s_print_in_hex():
    routine = load_spec(ROOT / "examples" / "pointer_record" / "in_span.toml")
    assert describe_case(routine, (0x2A0F, 10, 3, 200)) == "span=$2A0F, coordinate=10, left=3, width=200"
    routine = load_spec(ROOT / "examples" / "stack_args" / "absdiff.toml")
    assert describe_case(routine, (0xF0, 1, 2)) == "s=$F0, first=1, second=2"
