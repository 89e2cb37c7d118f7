"""CIA 1's timers and the ROM routine stubs of a C64 program run (retro.chips.cia.timers,
retro.machines.c64_stubs): each rule against the 6526 data sheet's text or the ROM's documented
behaviour, worked by hand; programs built byte by byte and run through `retro run`."""

from __future__ import annotations

import pytest

from retro.chips.cia.timers import Cia1Timers
from retro.commands import run
from retro.errors import RunError
from retro.machines.c64_stubs import screen_code

TA_LO, TA_HI, TB_LO, TB_HI, ICR, CRA, CRB = 0xDC04, 0xDC05, 0xDC06, 0xDC07, 0xDC0D, 0xDC0E, 0xDC0F


def counter(cia: Cia1Timers, cycle: int, lo: int = TA_LO) -> int:
    return cia.read(lo, cycle) | cia.read(lo + 1, cycle) << 8


def test_a_started_timer_counts_one_per_cycle_after_the_write_that_starts_it():
    cia = Cia1Timers()
    cia.write(TA_LO, 0xFE, 10)
    cia.write(TA_HI, 0xFE, 11)  # stopped: the high byte write loads the counter
    assert counter(cia, 12) == 0xFEFE
    cia.write(CRA, 0x11, 20)  # start, force load
    assert counter(cia, 20) == 0xFEFE
    assert counter(cia, 21) == 0xFEFD
    assert counter(cia, 20 + 16110) == 0xFEFE - 16110


def test_the_latch_goes_into_the_counter_only_when_stopped_or_forced():
    cia = Cia1Timers()
    cia.write(TA_LO, 0x10, 0)
    cia.write(TA_HI, 0x00, 0)
    cia.write(CRA, 0x01, 0)  # start without load: the counter holds $0010
    cia.write(TA_HI, 0x20, 5)  # running: the latch changes, the counter goes on
    assert counter(cia, 6) == 0x10 - 6
    cia.write(CRA, 0x11, 7)  # force load
    assert counter(cia, 7) == 0x2010


def test_a_continuous_timer_reloads_after_showing_zero_and_flags_the_underflow():
    cia = Cia1Timers()
    cia.write(TA_LO, 3, 0)
    cia.write(TA_HI, 0, 0)
    cia.write(CRA, 0x11, 0)
    values = []
    for cycle in range(1, 10):
        values.append(cia.read(TA_LO, cycle))
    assert values == [2, 1, 0, 3, 2, 1, 0, 3, 2]  # period latch + 1
    assert cia.read(ICR, 10) == 0x01  # the flag, no interrupt enabled: bit 7 clear
    assert cia.read(ICR, 11) == 0x00  # reading cleared it


@pytest.mark.parametrize("cycle, value", [(3 + 4 * 5, 0), (4 + 4 * 5, 3), (6 + 4 * 1000, 1)])
def test_a_continuous_timer_read_after_many_periods(cycle, value):
    cia = Cia1Timers()
    cia.write(TA_LO, 3, 0)
    cia.write(TA_HI, 0, 0)
    cia.write(CRA, 0x11, 0)
    assert cia.read(TA_LO, cycle) == value


def test_a_one_shot_timer_stops_at_its_underflow_with_the_latch_loaded():
    cia = Cia1Timers()
    cia.write(TB_LO, 2, 0)
    cia.write(TB_HI, 0, 0)
    cia.write(CRB, 0x19, 0)  # start, one-shot, force load
    assert cia.read(CRB, 1) & 0x01 == 1
    assert counter(cia, 10, TB_LO) == 2
    assert cia.read(CRB, 10) & 0x01 == 0  # START cleared by the underflow
    assert cia.read(ICR, 10) == 0x02
    assert cia.read(CRB, 10) & 0x10 == 0  # force load reads back 0


def test_a_stopped_timer_holds_its_count():
    cia = Cia1Timers()
    cia.write(TA_HI, 0x01, 0)  # latch $01FF, loaded
    cia.write(CRA, 0x01, 0)
    cia.write(CRA, 0x00, 100)
    assert counter(cia, 5000) == 0x01FF - 100


def test_letting_a_cia_interrupt_through_is_refused():
    cia = Cia1Timers()
    cia.write(ICR, 0x7F, 0)
    cia.write(ICR, 0x81, 1)  # enabled while timer A is stopped: nothing can come yet
    with pytest.raises(RunError, match="interrupt the CPU"):
        cia.write(CRA, 0x01, 2)


def test_registers_not_modelled_are_refused_on_read():
    with pytest.raises(RunError, match=r"\$DC01"):
        Cia1Timers().read(0xDC01, 0)


def test_screen_codes_of_printable_characters():
    assert [screen_code(c) for c in b"A@ 0["] == [1, 0, 0x20, 0x30, 0x1B]
    assert screen_code(0xC1) == 0x41 and screen_code(0xA0) == 0x60 and screen_code(0xFF) == 0x5E


def _program(tmp_path, code: bytes, data: bytes = b"") -> object:
    """`10 SYS 2061` then `code`, then `data` at its end."""
    line = b"\x0a\x00\x9e2061\x00"
    stub = (0x0801 + 2 + len(line)).to_bytes(2, "little") + line + b"\0\0"
    path = tmp_path / "p.prg"
    path.write_bytes(b"\x01\x08" + stub + code + data)
    return path


def test_strout_and_linprt_print_to_the_screen_and_the_transcript(tmp_path):
    text_at = 0x080D + 15
    code = bytes([0xA9, text_at & 0xFF, 0xA0, text_at >> 8, 0x20, 0x1E, 0xAB,  # LDA/LDY, JSR STROUT
                  0xA9, 0x01, 0xA2, 0x38, 0x20, 0xCD, 0xBD,  # LDA #1 LDX #$38 JSR LINPRT
                  0x60])
    text = bytes([147]) + b"HI" + bytes([13]) + b"AB" + bytes([0x22]) + b"NOT PRINTED" + bytes([0])
    report = run.run_c64_program(_program(tmp_path, code, text), frames=1)
    assert report.stopped == "returned"
    assert report.printed == ["{clr}HI", "AB 312"]
    memory = report.machine.memory
    assert memory[0x0400:0x0402] == [8, 9]
    assert memory[0x0428:0x042E] == [1, 2, 0x20, 0x33, 0x31, 0x32]
    assert memory[0xD828] & 0x0F == 14  # the colour after RUN: light blue
    assert (memory[0xD3], memory[0xD6], memory[0xD1] | memory[0xD2] << 8) == (6, 1, 0x0428)
    assert any(line == "printed: AB 312" for line in run.lines(report))


def test_ioinit_masks_cia_1_and_stops_its_timers(tmp_path):
    code = bytes([0xA9, 0x11, 0x8D, 0x0E, 0xDC,  # LDA #$11 STA $DC0E: timer A runs
                  0x20, 0xA3, 0xFD,  # JSR IOINIT
                  0xAD, 0x0E, 0xDC, 0x85, 0xFB,  # LDA $DC0E STA $FB
                  0x60])
    report = run.run_c64_program(_program(tmp_path, code), frames=1)
    assert report.stopped == "returned" and report.machine.memory[0xFB] == 0x08


def test_a_rom_routine_without_a_stub_is_still_refused(tmp_path):
    code = bytes([0x20, 0xD2, 0xFF, 0x60])  # JSR CHROUT
    with pytest.raises(RunError, match=r"\$FFD2 \(CHROUT\)"):
        run.run_c64_program(_program(tmp_path, code), frames=1)


def test_a_trace_names_the_stub_not_the_trap_byte(tmp_path):
    code = bytes([0xA9, 0x00, 0xA0, 0x00, 0x20, 0x1E, 0xAB, 0x60])  # print the empty text at $0000
    report = run.run_console_or_refuse(_program(tmp_path, code), frames=1, trace=True, trace_limit=10)
    assert any("$AB1E  STROUT (stub)" in line for line in run.program_trace_lines(report, False))
