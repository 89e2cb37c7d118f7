"""NMI when `$2000` bit 7 is set while the vblank flag is already set, after blargg's NES test ROM
ppu_vbl_nmi/04-nmi_control (its tests 5-11, replayed with our own programs): the NMI occurs at once,
only once per enable, again after a disable and enable, not at all once a $2002 read cleared the
flag; and "immediate occurrence should be after NEXT instruction" (test 11).

Timing by hand: the PPU starts at line 0 dot 0 with the CPU; the vblank flag is set at line 241 dot
1 = dot 82,182, seen from CPU cycle 27,394, and cleared at line 261 dot 1 = dot 89,002 (CPU cycle
29,667). The delay below (LDY #0 2, LDX #22 2, then 22 x (256 x DEY/BNE 5 - 1 + DEX/BNE 5) - 1)
ends at cycle 4 + 22 x 1,284 - 1 = 28,251: inside the vblank, with NMI still disabled.
"""

from __future__ import annotations

from retro.machines.nes import build_nes

ORIGIN = 0xC000
DELAY = [0xA0, 0x00, 0xA2, 22, 0x88, 0xD0, 0xFD, 0xCA, 0xD0, 0xFA]  # LDY #0, LDX #22, DEY/BNE, DEX/BNE
NMI_HANDLER = 0xC100  # INC $10, RTI
LDA_80, LDA_00, STA_2000, RTS = [0xA9, 0x80], [0xA9, 0x00], [0x8D, 0x00, 0x20], [0x60]


def run(body: list[int]):
    machine = build_nes()
    machine.poke(ORIGIN, DELAY + body + [0xEA] * 8 + RTS)
    machine.poke(NMI_HANDLER, [0xE6, 0x10, 0x40])
    machine.poke(0xFFFA, [NMI_HANDLER & 0xFF, NMI_HANDLER >> 8])
    machine.poke(0x10, [0])
    result = machine.call(ORIGIN, trace=True)
    return result, machine.peek(0x10)[0]


def test_the_delay_ends_inside_the_vblank_without_an_nmi():
    result, count = run([])
    assert count == 0
    assert result.cycles == 4 + 22 * 1284 - 1 + 8 * 2 + 6


def test_enabling_nmi_while_the_vblank_flag_is_set_gives_one_nmi_at_once():
    result, count = run(LDA_80 + STA_2000)  # blargg test 5
    assert count == 1
    names = [e.mnemonic for e in result.trace]
    assert names.index("NMI") <= names.index("STA") + 2  # at once: after the STA or the next instruction


def test_writing_80_again_while_enabled_gives_no_second_nmi():
    _, count = run(LDA_80 + STA_2000 + STA_2000)  # blargg tests 7 and 8
    assert count == 1


def test_disabling_and_enabling_again_gives_a_second_nmi():
    _, count = run(LDA_80 + STA_2000 + LDA_00 + STA_2000 + LDA_80 + STA_2000)  # blargg test 10
    assert count == 2


def test_no_nmi_once_a_2002_read_cleared_the_flag():
    _, count = run([0xAD, 0x02, 0x20] + LDA_80 + STA_2000)  # LDA $2002 first: blargg test 6
    assert count == 0


def test_the_immediate_nmi_comes_after_the_next_instruction():
    # blargg test 11: LDX #0, LDA #$80, STA $2000 (writes in its last cycle, after its poll), STX $10
    # (polls with the edge seen: the NMI follows it), LDA $10 reads the handler's count: 1.
    result, _ = run([0xA2, 0x00] + LDA_80 + STA_2000 + [0x86, 0x10, 0xA5, 0x10])
    assert result.a == 1
