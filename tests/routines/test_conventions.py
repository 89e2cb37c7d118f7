"""Calling conventions (docs/specs.md, "Calling conventions"): values on the stack (`3,S`), in a slot
of a table picked by an index input (`obj_x,X`), behind a pointer (`(ptr)`, `(ptr)+N`, `(ptr),Y`);
as inputs and as outputs, on both engines, with the same report; and every bad key one line.

The routines below are written so that a wrong convention gives a wrong answer: each test that
expects a failure runs a variant that reads (or writes) one place off.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from retro.cli import main
from retro.routines.runner import RoutineRunner
from retro.routines.spec import load_spec
from retro.testing import check

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
ENGINES = ("scalar", "batch")


def summary(report) -> tuple:
    """What both engines must report alike."""
    t = report.totals
    return (t.cases, t.result_mismatches, t.run_errors, t.cycles_min, t.cycles_max, t.cycles_sum, t.examples,
            t.min_case, t.max_case)


def both(spec, **options) -> tuple:
    reports = [check(spec, engine=engine, **options) for engine in ENGINES]
    assert reports[0].engine == "scalar" and reports[1].engine == "batch"
    assert summary(reports[0]) == summary(reports[1])
    return reports[0]


def copy_example(tmp_path: Path, name: str) -> Path:
    folder = tmp_path / name
    shutil.copytree(EXAMPLES / name, folder)
    return folder


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


# ---- the examples --------------------------------------------------------------------------------

@pytest.mark.parametrize("spec", ["stack_args/absdiff.toml", "object_table/hit_slot.toml",
                                  "pointer_record/in_span.toml"])
def test_examples_pass_on_both_engines_alike(spec):
    report = both(EXAMPLES / spec)
    assert report.mismatches == 0
    assert report.totals.cases > 4000


def test_stack_arguments_move_with_s(tmp_path):
    """With S up to $FF the caller's bytes wrap to the bottom of page 1, where `LDA $0104,X` does not
    look: the check finds it (and only for those S values)."""
    folder = copy_example(tmp_path, "stack_args")
    edit(folder / "absdiff.toml", '"$80..$FB"', '"$80..$FF"')
    report = both(folder / "absdiff.toml")
    assert report.totals.result_mismatches > 0
    assert all("s=$FC" in e or "s=$FD" in e or "s=$FE" in e or "s=$FF" in e for e in report.totals.examples)


def test_a_fixed_s_moves_the_arguments(tmp_path):
    folder = copy_example(tmp_path, "stack_args")
    spec = folder / "absdiff.toml"
    edit(spec, 's = { at = "S", values = "$80..$FB" }   # S at entry: any depth whose pushed bytes stay in page 1\n', "")
    edit(spec, 'entry = "absdiff"', 'entry = "absdiff"\ns = "$F0"')
    edit(folder / "refs.py", "def absdiff(s, first, second)", "def absdiff(first, second)")
    routine = load_spec(spec)
    runner = RoutineRunner(routine)
    assert runner.run((200, 13))[0] == (187,)
    memory = runner.machine.memory
    assert (memory[0x1F4], memory[0x1F3]) == (200, 13)  # 4,S and 3,S with S = $F0
    assert both(spec).mismatches == 0
    wrapped = folder / "wrapped.toml"  # a new file: runners are cached by the spec's path
    wrapped.write_text(spec.read_text().replace('s = "$F0"', 's = "$FE"'))  # the caller's bytes wrap to $0101/$0102
    assert both(wrapped).totals.result_mismatches > 0


def test_every_slot_is_checked_and_the_others_hold_other_values():
    routine = load_spec(EXAMPLES / "object_table" / "hit_slot.toml")
    runner = RoutineRunner(routine)
    base = routine.program.symbols["obj_x"]
    for slot in range(8):
        runner.run((slot, 100, 50, 100, 50))
        table = runner.machine.memory[base:base + 8]
        assert table[slot] == 100
        assert all(v != 100 for i, v in enumerate(table) if i != slot)
    report = both(EXAMPLES / "object_table" / "hit_slot.toml")
    slots = {case[0] for case in (report.totals.min_case, report.totals.max_case)}
    assert slots <= set(range(8))


@pytest.mark.parametrize("wrong", ["lda obj_x+1,x", "lda obj_x,y"])
def test_reading_the_wrong_slot_fails(tmp_path, wrong):
    folder = copy_example(tmp_path, "object_table")
    edit(folder / "hit_slot.s", "        lda obj_x,x\n", f"        {wrong}\n")
    report = both(folder / "hit_slot.toml")
    assert report.totals.result_mismatches > 0


def test_a_pointer_record_one_byte_off_fails(tmp_path):
    folder = copy_example(tmp_path, "pointer_record")
    edit(folder / "in_span.s", "        ldy #0\n", "        ldy #1\n")
    assert both(folder / "in_span.toml").totals.result_mismatches > 0


# ---- (ptr),Y, fixed pointers and outputs placed by the case ---------------------------------------

ROUTINES = """\
        .org $c000
        .alias ptr $fb
        .alias fixed $fd
load_y: lda (ptr),y     ; A = the byte Y bytes behind the pointer
        rts
load_fixed:
        ldy #3
        lda (fixed),y
        rts
mark:   lda #1          ; hits,X = 1: the slot X of the hits table
        sta hits,x
        rts
mark_wrong:
        lda #1
        sta hits+1,x
        rts
put:    ldy #2          ; (ptr)+2 = A
        sta (ptr),y
        rts
push_back:              ; 3,S = 3,S + 1: a result handed back in the caller's stack byte
        tsx
        inc $0103,x
        rts
sum3:   ldy #0          ; A = the sum of the three bytes behind the pointer (modulo 256)
        lda (ptr),y
        iny
        clc
        adc (ptr),y
        iny
        clc
        adc (ptr),y
        rts
word:   lda words,x     ; A = the high byte of the 16-bit word in slot X (X = 0, 2, 4, ...)
        rts
hits:   .byte 0, 0, 0, 0, 0, 0, 0, 0
words:  .byte 0, 0, 0, 0, 0, 0, 0, 0
"""

REFS = """\
def same(**kw):
    return kw["value"]

def one(**kw):
    return 1

def plus_one(**kw):
    return (kw["value"] + 1) & 0xFF

def total(**kw):
    return sum(kw["t"]) & 0xFF

def high(**kw):
    return kw["w"] >> 8
"""


def spec_file(tmp_path: Path, body: str, name: str = "spec") -> Path:
    """The spec in a file of its own name (runners are cached by the spec's path: one name, one spec)."""
    (tmp_path / "routines.s").write_text(ROUTINES)
    (tmp_path / "refs.py").write_text(REFS)
    path = tmp_path / f"{name}.toml"
    path.write_text(body)
    return path


LOAD_Y = """\
[program]
file = "routines.s"
entry = "load_y"

[inputs]
ptr = { at = "ptr", size = 2, values = "$3000..$30FF" }
y = { at = "Y", values = "0..15" }
value = { at = "(ptr),Y" }

[outputs]
a = "A"

[reference]
function = "refs.py:same"

[cases]
random = 3000
"""


def test_pointer_plus_y(tmp_path):
    report = both(spec_file(tmp_path, LOAD_Y))
    assert report.mismatches == 0
    assert "ptr=$30" in report.totals.examples[0] if report.totals.examples else True
    routine = load_spec(tmp_path / "spec.toml")
    runner = RoutineRunner(routine)
    assert runner.run((0x3010, 5, 0x99))[0] == (0x99,)
    assert runner.machine.memory[0x3015] == 0x99
    runner.run((0x3040, 1, 0x11))  # the byte of the call before is back to what it was
    assert runner.machine.memory[0x3015] == runner.call_image[0x3015]


def test_a_fixed_zero_page_pointer_set_by_a_memory_block(tmp_path):
    body = LOAD_Y.replace('entry = "load_y"', 'entry = "load_fixed"').replace(
        'ptr = { at = "ptr", size = 2, values = "$3000..$30FF" }\ny = { at = "Y", values = "0..15" }\n', "").replace(
        '(ptr),Y', '(fixed)+3') + '\n[memory]\nfixed = { at = "$fd", bytes = [ "$00", "$40" ] }\n'
    report = both(spec_file(tmp_path, body))
    assert report.mismatches == 0
    runner = RoutineRunner(load_spec(tmp_path / "spec.toml"))
    runner.run((0x77,))
    assert runner.machine.memory[0x4003] == 0x77


MARK = """\
[program]
file = "routines.s"
entry = "mark"

[inputs]
slot = { at = "X", values = "0..7" }

[outputs]
hit = { at = "hits,X" }

[reference]
function = "refs.py:one"

[cases]
exhaustive = ["slot"]
random = 0
"""


def test_an_output_in_a_slot(tmp_path):
    assert both(spec_file(tmp_path, MARK, "mark")).mismatches == 0
    wrong = both(spec_file(tmp_path, MARK.replace('entry = "mark"', 'entry = "mark_wrong"'), "wrong"))
    assert wrong.totals.result_mismatches == 8  # the slot read back holds its old 0 every time


def test_an_output_behind_a_pointer_and_on_the_stack(tmp_path):
    put = """\
[program]
file = "routines.s"
entry = "put"

[inputs]
ptr = { at = "ptr", size = 2, values = "$3000..$3FFF" }
value = "A"

[outputs]
stored = { at = "(ptr)+2" }

[reference]
function = "refs.py:same"

[cases]
random = 2000
"""
    report = both(spec_file(tmp_path, put.replace("stored", "value_out").replace('"refs.py:same"', '"refs.py:same"')))
    assert report.mismatches == 0
    stack = """\
[program]
file = "routines.s"
entry = "push_back"

[inputs]
s = { at = "S", values = "$10..$F0" }
value = { at = "3,S" }

[outputs]
back = { at = "3,S" }

[reference]
function = "refs.py:plus_one"

[cases]
exhaustive = ["value"]
random = 500
"""
    assert both(spec_file(tmp_path, stack, "stack")).mismatches == 0


def test_a_table_behind_a_pointer_and_a_word_in_a_slot(tmp_path):
    sum3 = """\
[program]
file = "routines.s"
entry = "sum3"

[inputs]
ptr = { at = "ptr", size = 2, values = "$5000..$50FF" }
t = { at = "(ptr)", size = 3, values = "0..255" }

[outputs]
a = "A"

[reference]
function = "refs.py:total"

[cases]
random = 2000

[entry]
d = 0
"""
    assert both(spec_file(tmp_path, sum3, "sum3")).mismatches == 0
    # a word in slots 0, 2, 4, 6; the routine reads its high byte with `lda words+1,x` only if right
    word = """\
[program]
file = "routines.s"
entry = "word"

[inputs]
slot = { at = "X", values = [0, 2, 4, 6] }
w = { at = "words,X", size = 2, values = "0..65535" }

[outputs]
a = "A"

[reference]
function = "refs.py:high"

[cases]
random = 2000
"""
    assert both(spec_file(tmp_path, word, "word")).totals.result_mismatches > 0  # it reads the low byte
    right = spec_file(tmp_path, word, "word_right")
    (tmp_path / "routines.s").write_text(ROUTINES.replace("word:   lda words,x", "word:   lda words+1,x"))
    assert both(right).mismatches == 0


# ---- bad values of every new key: one line naming the file and the key, exit 2 --------------------

BAD = [
    ('value = { at = "(ptr),Y" }', 'value = { at = "2,S" }', "inputs.value.at", "return address"),
    ('value = { at = "(ptr),Y" }', 'value = { at = "hits,X" }', "inputs.value.at", "X is not an input"),
    ('value = { at = "(ptr),Y" }', 'value = { at = "(nowhere),Y" }', "inputs.value.at", "unknown label"),
    ('value = { at = "(ptr),Y" }', 'value = { at = "(ptr),X" }', "inputs.value.at", "is not a place"),
    ('value = { at = "(ptr),Y" }', 'value = { at = "(y)" }', "inputs.value.at", "not a pointer"),
    ('ptr = { at = "ptr", size = 2, values = "$3000..$30FF" }', 'ptr = { at = "ptr", values = "0..255" }',
     "inputs.value.at", "inputs.ptr is not a pointer"),
    ('ptr = { at = "ptr", size = 2, values = "$3000..$30FF" }', 'low = { at = "ptr", values = "0..255" }',
     "inputs.value.at", "split over inputs.low"),
    ('ptr = { at = "ptr", size = 2, values = "$3000..$30FF" }', 'ptr = { at = "ptr", size = 2, values = "$FFF8..$FFFF" }',
     "inputs.value.at", "past $FFFF"),
    ('ptr = { at = "ptr", size = 2, values = "$3000..$30FF" }', 'ptr = { at = "ptr", size = 2, values = "$00F0..$00FF", table = false }',
     "inputs.value.at", "may reach $00FB, where inputs.ptr goes"),
    ('y = { at = "Y", values = "0..15" }', 'y = { at = "Y", values = "0..15" }\nz = { at = "$3005" }',
     "inputs.value.at", "inputs.z"),
    ('[reference]', 'other = { at = "(ptr)+4" }\n\n[reference]', "outputs.other", None),
    ('entry = "load_y"', 'entry = "load_y"\ns = 256', "program.s", "256"),
    ('entry = "load_y"', 'entry = "load_y"\ns = "top"', "program.s", None),
    ('a = "A"', 'a = "S"', "outputs.a.at", "not an output"),
    ('y = { at = "Y", values = "0..15" }', 'y = { at = "Y", values = "0..15" }\nw = { at = "$4000", size = 4 }',
     "inputs.w.size", "32-bit number, or a table of 4 bytes"),
    ('y = { at = "Y", values = "0..15" }', 'y = { at = "Y", values = "0..15" }\nq = { at = ["S", "A"] }',
     "inputs.q.at", "S is one byte"),
]


@pytest.mark.parametrize("old,new,key,words", BAD)
def test_bad_keys_are_one_line_naming_the_file_and_key(tmp_path, capsys, old, new, key, words):
    body = LOAD_Y.replace(old, new) + '\n[memory]\nblock = { at = "$3200", fill = 0, size = 16 }\n'
    if key == "outputs.other":  # an output at a pointer is fine; reaching into a block is not for inputs
        body = body.replace('other = { at = "(ptr)+4" }', "").replace(
            'value = { at = "(ptr),Y" }', 'value = { at = "(ptr),Y" }\nwide = { at = "(ptr)+$200" }')
        key, words = "inputs.wide.at", "memory.block"
    path = spec_file(tmp_path, body)
    assert main(["check", str(path), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert str(path) in err and key in err, err
    if words:
        assert words in err, err
