"""The project's datasheet timing table, the per-trace model, the static analysis and call_fast."""

from __future__ import annotations

import pytest

from retro.assembler import assemble_text
from retro.cpu.flow import analyse
from retro.cpu.machine import ENTRY_S, Machine
from retro.cpu.mpu import MPU6510
from retro.cpu.timing import OPCODES, model_cycles
from retro.errors import InputError


def test_table_agrees_with_the_emulator_on_every_opcode_it_lists():
    # Two independent sources: the datasheet/64doc table kept here and the cycle-exact emulator
    # (itself checked against the SingleStepTests vectors).
    for opcode, op in OPCODES.items():
        assert MPU6510.cycletime[opcode] == op.cycles, f"${opcode:02X} {op.mnemonic}"


def test_hand_counted_penalties():
    # LDA $10F0,X with X = $20 crosses into $11xx: 4 + 1. BNE taken to another page: 2 + 1 + 1.
    source = """
        .org $10f8
        lda $10f0,x
        bne far
        rts
        nop
        nop
    far: rts            ; $1100: the first byte of the next page
    """
    program = assemble_text(source)
    machine = Machine()
    machine.load(program)
    memory = machine.memory
    assert program.symbols["far"] == 0x1100
    steps = [(0x10F8, 0x20, 0, 0x20, 0), (0x10FB, 0x20, 0, 0x20, 0), (0x1100, 0x20, 0, 0x20, 0)]
    assert model_cycles(memory.__getitem__, steps) == (4 + 1) + (2 + 1 + 1) + 6
    memory[0x10F0 + 0x20] = 1  # non-zero: the branch is taken in the real run too
    cycles, *_ = machine.call_fast(0x10F8, x=0x20)
    assert cycles == 4 + 1 + 2 + 1 + 1 + 6


def test_call_fast_equals_call(runners):
    runner = runners["circle"]
    machine = runner.machine
    for case in ((10, 20, 5, 14, 23, 1), (0, 0, 0, 255, 255, 255), (200, 3, 40, 190, 60, 30)):
        writes, registers, _ = runner.inputs_for_call(case)
        assert registers == {"a": case[0], "x": case[2], "y": 0, "s": ENTRY_S}  # x1 in A, r1 in X (asm/circle.toml)
        assert writes == [(0x11, case[1]), (0x13, case[3]), (0x14, case[4]), (0x15, case[5])]
        fast = machine.call_fast(runner.entry, writes, **registers)
        slow = machine.call(runner.entry, memory={address: [value] for address, value in writes}, **registers)
        assert fast == (slow.cycles, slow.a, slow.x, slow.y, slow.p)


def test_static_bounds_of_a_hand_counted_routine():
    source = """
        .org $c000
    entry:
        ldx #3          ; 2
    loop:
        dex             ; 2 each
        bne loop        ; 3 taken (same page), 2 falling through
        lda $10         ; 3
        beq done        ; 2 / 3
        nop             ; 2
    done:
        rts             ; 6
    """
    program = assemble_text(source)
    memory = [0] * 0x10000
    memory[program.origin:program.end] = program.code
    loop = program.symbols["loop"]
    bounds = analyse(memory.__getitem__, program.symbols["entry"], {loop: 3})
    # X = 3 is known, so the loop runs exactly three times (taken twice, then falls through):
    # 2 + (2+3) + (2+3) + (2+2) = 16, LDA 3 = 19; $10 is unknown (only the code is known by default):
    # best: BEQ taken 3, RTS 6 = 28; worst: BEQ 2, NOP 2, RTS 6 = 29
    assert (bounds.best, bounds.worst) == (28, 29)
    # with X unknown (read from $11), the bound of 3 is all that limits the loop: it runs 1 to 3 times
    unknown = list(memory)
    unknown[program.symbols["entry"]:program.symbols["entry"] + 2] = [0xA6, 0x11]  # ldx $11 (3 cycles)
    bounds = analyse(unknown.__getitem__, program.symbols["entry"], {loop: 3})
    # best: 3 + (2+2) + 3 + 3 + 6 = 19; worst: 3 + (2+3)*2 + (2+2) + 3 + 2 + 2 + 6 = 30
    assert (bounds.best, bounds.worst) == (19, 30)
    with pytest.raises(InputError, match="needs a bound"):
        analyse(memory.__getitem__, program.symbols["entry"], {})


def test_measured_run_of_the_hand_counted_routine_lies_inside():
    source = """
        .org $c000
    entry:
        ldx #3
    loop:
        dex
        bne loop
        lda $10
        beq done
        nop
    done:
        rts
    """
    program = assemble_text(source)
    machine = Machine()
    machine.load(program)
    cycles, *_ = machine.call_fast(program.symbols["entry"], [(0x10, 1)])
    assert cycles == 2 + (2 + 3) * 2 + 2 + 2 + 3 + 2 + 2 + 6  # three loop passes, nop executed
