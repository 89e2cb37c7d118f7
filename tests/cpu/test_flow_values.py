"""Value ranges in the static analysis (retro.cpu.flow over retro.cpu.values): small routines whose
cycles are counted by hand from the datasheet table (LDA abs 4, abs,X/abs,Y 4 +1 across a page, LDA
# 2, LDX/LDY # 2, STA abs 4, branches 2, +1 taken, +1 more into another page, RTS 6, NOP 2)."""

from __future__ import annotations

import pytest

from retro.assembler import assemble_text
from retro.cpu.flow import Fact, analyse
from retro.cpu.values import ANY, MemoryModel, State, single, span
from retro.errors import InputError


def _bounds(source: str, state: State | None = None, known: dict[int, int] | None = None, facts=None,
            loops=None, entry: str = "entry"):
    """(best, worst) of the routine at `entry`; memory: the program's bytes, `known` bytes, else unknown."""
    program = assemble_text(".org $c000\n" + source)
    image = [0] * 0x10000
    image[program.origin:program.end] = program.code
    known = dict(known or {})

    def initial(address: int) -> int:
        if program.origin <= address < program.end:
            return single(image[address])
        return single(known[address]) if address in known else ANY
    bounds = analyse(image.__getitem__, program.symbols[entry], {program.symbols[k]: v for k, v in (loops or {}).items()},
                     memory=MemoryModel(initial, (program.origin, program.end)), entry_state=state,
                     facts={program.symbols[k]: v for k, v in (facts or {}).items()})
    return bounds.best, bounds.worst, program


def test_a_known_index_never_crosses():
    # tbl at $C0FF: LDA tbl,Y crosses for every Y >= 1
    source = "entry: ldy #0\n lda tbl,y\n rts\n .advance $c0ff\ntbl: .byte 1, 2\n"
    assert _bounds(source)[:2] == (2 + 4 + 6, 2 + 4 + 6)
    unknown = "entry: lda tbl,y\n rts\n .advance $c0ff\ntbl: .byte 1, 2\n"
    assert _bounds(unknown)[:2] == (4 + 6, 4 + 1 + 6)


@pytest.mark.parametrize("x, cycles", [(1, 4 + 6), (2, 5 + 6), (3, 5 + 6)])
def test_a_fixed_register_gives_the_exact_cost(x, cycles):
    # obj at $C0FE: obj + 1 = $C0FF stays in the page, obj + 2 = $C100 crosses
    source = "entry: lda obj,x\n rts\n .advance $c0fe\nobj: .byte 0, 0, 0, 0\n"
    assert _bounds(source, State(x=single(x)))[:2] == (cycles, cycles)
    # a range: the crossing is possible, not certain
    assert _bounds(source, State(x=span(0, 3)))[:2] == (4 + 6, 5 + 6)
    # every value of the range crosses: certain (both bounds pay it)
    assert _bounds(source, State(x=span(2, 200)))[:2] == (5 + 6, 5 + 6)


def test_a_branch_whose_outcome_is_known_is_counted_one_way():
    # LDA #0 sets Z: BEQ is always taken (3), the NOP never runs
    source = "entry: lda #0\n beq done\n nop\ndone: rts\n"
    assert _bounds(source)[:2] == (2 + 3 + 6, 2 + 3 + 6)
    # a byte of unknown value: both ways
    source = "entry: lda $10\n beq done\n nop\ndone: rts\n"
    assert _bounds(source)[:2] == (3 + 3 + 6, 3 + 2 + 2 + 6)
    # the same byte known to memory (a constant table, an input's values): one way again
    assert _bounds(source, known={0x10: 5})[:2] == (3 + 2 + 2 + 6, 3 + 2 + 2 + 6)


def test_values_flow_through_transfers_counters_and_compares():
    # X = 5, INX -> 6, TXA, CMP #6 sets Z and C: BNE never taken, BCS always
    source = "entry: ldx #5\n inx\n txa\n cmp #6\n bne far\n bcs done\nfar: nop\ndone: rts\n"
    assert _bounds(source)[:2] == (2 + 2 + 2 + 2 + 2 + 3 + 6,) * 2
    # a loop over Y = 0..2 reading tbl at $C0FE: iterations 0 and 1 stay in the page, 2 crosses
    source = ("entry: ldy #0\nloop: lda tbl,y\n iny\n cpy #3\n bne loop\n rts\n"
              " .advance $c0fe\ntbl: .byte 0, 0, 0\n")
    # 2 + 3 x (4 + 2 + 2) + 1 crossing + 2 taken branches x 3 + the last 2 + RTS 6
    assert _bounds(source, loops={"loop": 3})[:2] == (2 + 3 * 8 + 1 + 2 * 3 + 2 + 6,) * 2


def test_stores_and_loads_of_memory_are_followed():
    # the routine stores 3 to $10 and indexes with it: LDX $10 = 3, LDA obj,X crosses ($C0FE + 3)
    source = "entry: lda #3\n sta $10\n ldx $10\n lda obj,x\n rts\n .advance $c0fe\nobj: .byte 0\n"
    assert _bounds(source)[:2] == (2 + 3 + 3 + 5 + 6,) * 2


def test_self_modified_operands_are_bounded_by_the_stored_values():
    # the low byte of LDA $C200,X comes from A: A, X in 0..15 never cross, any A may
    source = "entry: sta read+1\nread: lda $c200,x\n rts\n"
    assert _bounds(source, State(a=span(0, 15), x=span(0, 15)))[:2] == (4 + 4 + 6,) * 2
    assert _bounds(source, State(x=span(0, 15)))[:2] == (4 + 4 + 6, 4 + 5 + 6)
    # the bytes as loaded say $00 (never a crossing); what the routine stores there decides
    assert _bounds(source, State(a=single(0xF8), x=single(8)))[:2] == (4 + 5 + 6,) * 2


def test_a_rewritten_opcode_or_jump_cannot_be_bounded():
    with pytest.raises(InputError, match=r"store at \$C000 may rewrite the opcode of NOP at \$C003"):
        _bounds("entry: sta patch\npatch: nop\n rts\n")
    with pytest.raises(InputError, match=r"store at \$C000 may rewrite the target of BNE at \$C003"):
        _bounds("entry: sta skip+1\nskip: bne done\n nop\ndone: rts\n")


def test_stated_facts_prune_what_the_values_cannot():
    source = "entry: lda $10\ntest: beq done\n nop\ndone: rts\n"
    assert _bounds(source, facts={"test": Fact(taken=True)})[:2] == (3 + 3 + 6,) * 2
    assert _bounds(source, facts={"test": Fact(taken=False)})[:2] == (3 + 2 + 2 + 6,) * 2
    # a register's range at a label: X in 0..1 at `read` never crosses from $C0FE
    source = "entry: ldx $10\nread: lda obj,x\n rts\n .advance $c0fe\nobj: .byte 0\n"
    assert _bounds(source)[:2] == (3 + 4 + 6, 3 + 5 + 6)
    assert _bounds(source, facts={"read": Fact(registers=(("x", span(0, 1)),))})[:2] == (3 + 4 + 6,) * 2


def test_a_subroutine_is_analysed_from_the_state_at_its_call():
    # sub reads tbl,X at $C0FF: called with X = 0 it never crosses, with X = 1 it always does
    source = ("entry: ldx #0\n jsr sub\n ldx #1\n jsr sub\n rts\nsub: lda tbl,x\n rts\n"
              " .advance $c0ff\ntbl: .byte 0, 0\n")
    # 2 + (6 + 4 + 6) + 2 + (6 + 5 + 6) + 6
    assert _bounds(source)[:2] == (2 + 16 + 2 + 17 + 6,) * 2


def test_stores_pay_no_page_crossing():
    # STA abs,X takes 5 cycles whether or not obj + X crosses (opcodes.py: no page penalty): X = 2
    # from $C0FE crosses, and neither bound may count it (a best case above the real one would fail)
    source = "entry: ldx #2\n sta obj,x\n rts\n .advance $c0fe\nobj: .byte 0, 0, 0\n"
    assert _bounds(source)[:2] == (2 + 5 + 6, 2 + 5 + 6)


def test_a_compare_s_n_over_two_sets_is_every_pair_s_bit_7():
    """difference_sign (the windows of the operand's set) against the pairs enumerated, on sets of every size,
    the wrap-around ones (values near 0 and 255, the windows crossing the end of the byte) included."""
    import random

    from retro.cpu.value_steps import difference_sign
    from retro.cpu.values import CLEAR, EITHER, SET, flag_of, members

    rng = random.Random(24)
    sets = [single(0), single(255), single(128) | single(127), span(0, 127), span(128, 255), span(120, 135), ANY]
    sets += [sum(1 << v for v in rng.sample(range(256), k)) for k in (1, 2, 3, 5, 20, 60, 200) for _ in range(40)]
    for register in sets:
        for operand in rng.sample(sets, 30):
            pairs = {bool((r - m) & 0x80) for r in members(register) for m in members(operand)}
            assert difference_sign(register, operand) == flag_of(pairs), (register, operand)
    assert difference_sign(single(5), single(5)) == CLEAR and difference_sign(single(4), single(5)) == SET
    assert difference_sign(single(0), single(0) | single(1)) == EITHER


def test_a_changed_state_is_the_replaced_one_and_names_are_checked():
    from dataclasses import replace

    state = State(a=single(3), stored=((0x10, single(1)),))
    assert state.changed(a=ANY, c=1) == replace(state, a=ANY, c=1)
    assert hash(state.changed(x=single(2))) == hash(replace(state, x=single(2)))
    assert state.a == single(3)  # (a new state: the old one unchanged)
    with pytest.raises(TypeError, match="no field 'q'"):
        state.changed(q=1)
