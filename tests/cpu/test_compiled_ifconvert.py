"""If-conversion in the compiled engine (retro.cpu.ifconvert finds the regions, retro.cpu.translate emits
them): short branches whose two ways are both run and one kept by selection. Each shape the translator
converts (a triangle over a store, a diamond joined by a JMP, ways ending at RTS, nested branches, a
backward branch inside a way, a branch into another page, the 65C02's BBR and BRA) is asserted to be
converted, then run on random registers, flags (decimal mode included) and memory on the compiled
engine, the batched core and Machine: registers, flags, cycles and every watched byte must agree."""

from __future__ import annotations

import pytest

from retro.assembler import assemble_file, assemble_text
from retro.cpu import ifconvert
from retro.cpu.compiled import numba_problem
from retro.cpu.machine import RETURN_TRAP, push_return_trap
from retro.cpu.translate import CONVERTED_NOTE, translate
from test_compiled import CODE, LANES, _three_engines, image_with, random_states

pytestmark = pytest.mark.skipif(numba_problem() is not None, reason=f"{numba_problem()}")

# (Data are read at even zero-page addresses: the random states put $03 or $04 at the odd ones, the
# high bytes of (zp) pointers, which would send a branch the same way on every call.)
# A triangle over a triangle over a store (the inner store is made only when both ways are the ones
# taken), triangles over fixed stores (zero page and absolute: made only on the way taken), a diamond
# joined by a JMP, a triangle over a V test, and a tree whose ways end at RTS with a triangle inside.
SHAPES = """
.org $C0A0
    lda $2E
    bmi s3
    ldx $3C
    beq s3
    sta $0312
s3: lda $20
    cmp $32
    bcc t1
    inc $22
    inx
t1: lda $34
    bpl d1
    eor #$FF
    sta $0310
    jmp j1
d1: ora $24
    ldy $36
j1: bit $26
    bvs t2
    tay
t2: cpy $38
    bne far
    lda $28
    beq z1
    adc #$10
z1: rts
far: sec
    sbc $3A
    rts
"""

# tile's shape: the taken way runs into a backward branch to code both ways share (no loop).
BACKWARD = """
.org $C0A0
    lda $2A
    beq empty
    bcs right
    ldy $2B
    bmi empty
good: lda $2C
    rts
right: ldy $2D
    bpl good
empty: lda #0
    rts
"""

# tile's own shape: the two ways each end at a branch of their own to the same two tails, too long to
# run twice each: the ways' branches are both evaluated, the one on the way taken chosen (a merged exit).
MERGED = """
.org $C0A0
    lda $2A
    beq empty
    bcs right
    ldy $2C
    bmi empty
good: lda ($30),y
    tax
    lda $0320,x
    rts
right: ldy $3E
    bpl good
empty: lda #0
    rts
"""

# Branches into another page inside converted ways: +2 cycles when taken (+1, and +1 for the page).
PAGES = """
.org $C0A0
    lda $20
    ldx $32
    jmp near
.advance $C0F8
near: cmp $22
    bcs over
    adc $34
    sta $24
over: cpx $36
    beq done
    dex
    stx $0311
done: rts
"""

# The 65C02's bit branch and BRA inside a way.
CMOS = """
.org $C0A0
    bbr3 $20, skip
    inc $21
    bra over
skip: ldx $22
over: stz $23
    bbs7 $24, late
    tsb $25
late: rts
"""


def _converted(code: bytes, cpu: str) -> set[int]:
    image = image_with(code)
    push_return_trap(image)
    source = translate(image.__getitem__, CODE, cpu, RETURN_TRAP, sets=((3, 0, 3),)).source
    return {int(line.split("$")[1][:4], 16) for line in source.splitlines() if CONVERTED_NOTE in line}


def _agree(cpu: str, code: bytes, seed: int) -> None:
    _, left = _three_engines(cpu, code, *random_states(seed, LANES))
    assert left == 0


def _assembled(text: str, cpu: str, tmp_path) -> tuple[bytes, dict]:
    if cpu == "65c02":
        source = tmp_path / "shape.s"
        source.write_text(text)
        program = assemble_file(source, cpu=cpu)
    else:
        program = assemble_text(text)
    assert program.origin == CODE
    return program.code, program.symbols


@pytest.mark.parametrize("name,text,cpu,branches", [
    ("shapes", SHAPES, "6510", 7),  # bmi s3, beq s3, bcc t1, bpl d1, bvs t2, bne far (RTS tree), beq z1
    ("backward", BACKWARD, "6510", 3),  # bcs right (both ways end at RTS), bmi empty, bpl good
    ("merged", MERGED, "6510", 2),  # bcs right with its ways' bmi / bpl merged
    ("pages", PAGES, "6510", 2),
    ("cmos", CMOS, "65c02", 2),
    ("shapes-2a03", SHAPES, "2a03", 7),
], ids=lambda value: value if isinstance(value, str) and "\n" not in value else "")
def test_converted_shapes_agree_on_all_three_engines(name, text, cpu, branches, tmp_path, compiled_cache):
    code, symbols = _assembled(text, cpu, tmp_path)
    converted = _converted(code, cpu)
    assert len(converted) >= branches, f"{name}: converted only {sorted(hex(pc) for pc in converted)}"
    for seed in range(2):
        _agree(cpu, code, seed)


def test_a_page_crossing_branch_is_converted(tmp_path):
    """PAGES's BCS at $C0FA goes to $C100, another page than the next instruction's: it is converted
    (so its taken +2 is in the selected cycles, which the agreement above checks)."""
    code, symbols = _assembled(PAGES, "6510", tmp_path)
    bcs = symbols["near"] + 2
    assert (bcs + 2) >> 8 != symbols["over"] >> 8
    assert bcs in _converted(code, "6510")


def test_no_loop_is_converted_and_a_big_region_is_left_branching(tmp_path):
    """A counted loop's backward branch stays a branch; a diamond whose ways cost more than MAX_COST does too."""
    loop = assemble_text(".org $C0A0\n    ldx #3\nl:  dex\n    bne l\n    rts\n").code
    assert _converted(loop, "6510") == set()
    long_way = "\n".join(["    lda $20"] + ["    adc $21"] * (ifconvert.MAX_COST + 1))
    big = assemble_text(f".org $C0A0\n    bcc skip\n{long_way}\nskip: rts\n").code
    assert _converted(big, "6510") == set()
    small = assemble_text(".org $C0A0\n    bcc skip\n    adc $21\nskip: rts\n").code
    assert _converted(small, "6510") == {CODE}


def test_a_way_with_a_computed_store_or_the_stack_is_not_converted():
    """A store through an index (logged, checked against the code) and a push stay behind a branch."""
    for body in ("    sta $20,x", "    pha\n    pla", "    jsr sub"):
        code = assemble_text(f".org $C0A0\n    bcc skip\n{body}\nskip: rts\nsub: rts\n").code
        assert _converted(code, "6510") == set(), body


def test_a_branch_with_one_way_to_rts_and_one_to_the_stack_keeps_its_jump(tmp_path, compiled_cache):
    """Ways that meet nowhere (one ends at an RTS, the other stops at a PHA) do not convert, and the
    code still agrees on all three engines."""
    code = assemble_text(".org $C0A0\n    lda $20\n    bcc stack\n    adc $21\n    rts\n"
                         "stack: pha\n    pla\n    eor #$55\n    rts\n").code
    assert _converted(code, "6510") == set()
    _agree("6510", code, 0)


def test_ways_ending_at_two_branches_to_the_same_tails_merge_them(tmp_path):
    """MERGED's BCS: each way ends at its own branch (BMI, BPL) to the same two tails; converting the
    ways with the tails inside each costs more than MAX_COST, merging them costs less."""
    code, symbols = _assembled(MERGED, "6510", tmp_path)
    image = image_with(code)
    push_return_trap(image)
    source = translate(image.__getitem__, CODE, "6510", RETURN_TRAP, sets=((3, 0, 3),)).source
    assert f"${symbols['right'] + 2:04X} and ${symbols['good'] - 2:04X}: the way taken's branch" in source


# A store whose address the code patches (a live operand: retro.cpu.translate.live_operands) inside a
# branch's way: its address is computed at run time, so it cannot be made conditional as a fixed store
# is; the branch keeps its jump (else the untaken way's patched store would write on every call).
PATCHED_STORE = """
.org $C0A0
    lda $20
    and #$1F
    ora #$40
    sta st+1
    lda $22
    bcc skip
st: sta $60
skip: rts
"""


def test_a_way_with_a_patched_store_is_not_converted_and_agrees(tmp_path, compiled_cache):
    code, symbols = _assembled(PATCHED_STORE, "6510", tmp_path)
    bcc = symbols["st"] - 2
    assert bcc not in _converted(code, "6510")
    unpatched = assemble_text(PATCHED_STORE.replace("    sta st+1\n", "    sta $0300\n")).code
    assert _converted(unpatched, "6510") == {bcc}  # the same branch over a fixed store converts
    for seed in range(2):
        _agree("6510", code, seed)
