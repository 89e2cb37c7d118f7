"""The opcode table (retro.cpu.opcodes) against the independent timing model, py65's own tables for the
documented opcodes, and the dispatch both emulators build from it."""

from __future__ import annotations

import pytest
from py65.devices.mpu6502 import MPU as Py65

from retro.cpu import batch
from retro.cpu.mpu import MPU2A03, MPU6510
from retro.cpu.opcodes import DOCUMENTED, JAM, OPCODE_TABLE, STABLE, UNSTABLE, opcodes_of
from retro.cpu.timing import OPCODES as DATASHEET

RUNNABLE = {**opcodes_of(DOCUMENTED), **opcodes_of(STABLE)}
ALIASES = {"USBC": "SBC"}  # the timing model names $EB apart from the documented SBC #imm
PY65_DEC_ABS = 0xCE  # py65 1.2.0 charges 3 cycles; the datasheet says 6


def test_every_opcode_has_one_row_and_the_kinds_add_up():
    assert sorted(OPCODE_TABLE) == list(range(256))
    # 151 documented opcodes (MOS programming manual); 12 JAM and 8 unstable ones (No More Secrets)
    assert (len(opcodes_of(DOCUMENTED)), len(opcodes_of(JAM)), len(opcodes_of(UNSTABLE))) == (151, 12, 8)
    assert len(opcodes_of(STABLE)) == 256 - 151 - 12 - 8


@pytest.mark.parametrize("opcode", sorted(RUNNABLE))
def test_each_runnable_row_equals_the_datasheet_model(opcode):
    row, model = OPCODE_TABLE[opcode], DATASHEET[opcode]
    assert (row.mnemonic, row.mode, row.cycles, row.page_penalty) == (
        ALIASES.get(model.mnemonic, model.mnemonic), model.mode, model.cycles, model.page_penalty)


def test_the_table_has_no_row_the_timing_model_lacks_or_adds():
    assert set(DATASHEET) == set(RUNNABLE)


@pytest.mark.parametrize("opcode", sorted(opcodes_of(DOCUMENTED)))
def test_documented_rows_match_py65(opcode):
    row = OPCODE_TABLE[opcode]
    mnemonic, mode = Py65.disassemble[opcode]
    assert (row.mnemonic, row.mode) == (mnemonic, mode)
    if opcode != PY65_DEC_ABS:
        assert row.cycles == Py65.cycletime[opcode]


@pytest.mark.parametrize("cpu", [MPU6510, MPU2A03])
def test_the_scalar_dispatch_is_built_from_the_table(cpu):
    for opcode, row in OPCODE_TABLE.items():
        assert tuple(cpu.disassemble[opcode]) == (row.mnemonic, row.mode), f"${opcode:02X}"
        if row.kind in (DOCUMENTED, STABLE):
            assert cpu.cycletime[opcode] == row.cycles, f"${opcode:02X}"


def test_the_batched_dispatch_covers_exactly_the_runnable_rows():
    assert set(batch.HANDLERS) == set(RUNNABLE)


@pytest.mark.parametrize("opcode, row", [
    # 64doc's undocumented opcode list, written out by hand
    (0x27, ("RLA", "zpg", 5, False, STABLE)), (0x2F, ("RLA", "abs", 6, False, STABLE)),
    (0xE3, ("ISC", "inx", 8, False, STABLE)), (0xB3, ("LAX", "iny", 5, True, STABLE)),
    (0x8F, ("SAX", "abs", 4, False, STABLE)), (0xFC, ("NOP", "abx", 4, True, STABLE)),
    (0xEB, ("SBC", "imm", 2, False, STABLE)), (0x9B, ("TAS", "aby", 5, False, UNSTABLE)),
    (0x02, ("JAM", "imp", 0, False, JAM)),
])
def test_rows_written_out_from_64doc(opcode, row):
    assert tuple(OPCODE_TABLE[opcode]) == row
