"""The PPU on the 2A03 machine's bus: registers, VRAM, OAM DMA, and $2002 timed by the CPU clock.

Timing expectations are worked out from the rules in retro.chips.ppu.clock (machine cycle c of a
machine whose PPU was attached at cycle 0 begins at PPU dot 3c on NTSC, 3.2c on PAL; an access in
cycle c sees events at dots <= that; frames are 262 x 341 dots, 341 x 262 - 1 for odd frames with
rendering on; vblank at line 241 dot 1, flags cleared at dot 1 of the pre-render line)."""

from __future__ import annotations

import math

from nes_build import make_state

from retro.assembler import assemble_text
from retro.chips.ppu.constants import PAL
from retro.chips.ppu.device import PpuDevice
from retro.cpu.machine import Machine
from retro.machines.nes import build_nes, ppu_of

FULL_FRAME = 262 * 341          # 89342
SHORT_FRAME = FULL_FRAME - 1


def ppu_machine(state=None) -> tuple[Machine, PpuDevice]:
    machine = build_nes(state or make_state(mask=0))
    return machine, ppu_of(machine)


def status(device: PpuDevice, cycle: int) -> int:
    return device.read(0x2002, cycle)


def test_vblank_flag_timing_and_read_clear():
    _, device = ppu_machine()
    vblank_dot = 241 * 341 + 1                       # 82182
    first = math.ceil(vblank_dot / 3)                # 27394: cycle 27394 begins at dot 82182
    assert status(device, first - 1) & 0x80 == 0
    assert status(device, first) & 0x80 == 0x80
    assert status(device, first + 1) & 0x80 == 0     # the read cleared it
    # Next frame (rendering off, no skipped dot): vblank again one full frame later.
    again = math.ceil((FULL_FRAME + vblank_dot) / 3)
    assert status(device, again - 1) & 0x80 == 0
    assert status(device, again) & 0x80 == 0x80


def test_vblank_cleared_at_pre_render_line_without_a_read():
    _, device = ppu_machine()
    clear_dot = 261 * 341 + 1
    assert device.peek(0x2002) & 0x80 == 0
    device.advance(clear_dot - 1)
    assert device.peek(0x2002) & 0x80 == 0x80
    device.advance(clear_dot)
    assert device.peek(0x2002) & 0x80 == 0


def test_odd_frames_with_rendering_on_are_one_dot_short():
    # Rendering on (sprite 0 below the screen, so no hit). Frame 0 is even: full; frame 1 odd: one
    # dot short. The vblank of frame 2 comes at 2 x 89342 - 1 + 82182 = 260865 = 3 x 86955.
    vblank_dot = 241 * 341 + 1
    first = math.ceil((2 * FULL_FRAME - 1 + vblank_dot) / 3)
    assert first == 86955
    _, device = ppu_machine(make_state(mask=0x18, sprite=(250, 1, 0, 0)))
    assert status(device, first - 1) & 0x80 == 0
    assert status(device, first) & 0x80 == 0x80
    # With rendering off all frames are full: that vblank is one dot later.
    later = math.ceil((2 * FULL_FRAME + vblank_dot) / 3)
    assert later == first + 1          # 260866 / 3 rounds up to the next cycle
    # (a read at cycle later - 1 would be one dot before that vblank and suppress it: peek instead)
    _, device = ppu_machine(make_state(mask=0x00))
    device.advance(3 * (later - 1))
    assert device.peek(0x2002) & 0x80 == 0
    assert status(device, later) & 0x80 == 0x80


def test_hit_flag_set_at_model_dot_not_cleared_by_reads_cleared_at_pre_render():
    state = make_state(cells={(0, 15, 16): 1}, sprite=(119, 1, 0, 128))
    _, device = ppu_machine(state)
    hit_dot = 120 * 341 + 129                       # line 120, dot x + 1
    first = math.ceil(hit_dot / 3)
    assert status(device, first - 1) & 0x40 == 0
    assert status(device, first) & 0x40 == 0x40
    assert status(device, first + 100) & 0x40 == 0x40          # reading never clears bit 6
    clear_cycle = math.ceil((261 * 341 + 1) / 3)
    assert status(device, clear_cycle - 1) & 0x40 == 0x40
    assert status(device, clear_cycle) & 0x40 == 0
    # Frame 1 hits again at the same line and dot (frame 0 was even: full length).
    again = math.ceil((FULL_FRAME + hit_dot) / 3)
    assert status(device, again - 1) & 0x40 == 0 and status(device, again) & 0x40 == 0x40


def test_register_mirrors_and_status_low_bits():
    _, device = ppu_machine()
    device.write(0x3FF8, 0x10, 10)       # $3FF8 mirrors $2000
    assert device.ctrl == 0x10
    device.write(0x2009, 0x1E, 11)       # $2009 mirrors $2001
    assert device.mask == 0x1E
    device.write(0x2000, 0x15, 12)
    assert status(device, 13) & 0x1F == 0x15    # low 5 bits: the last value on the PPU's bus


def test_scroll_registers_and_toggle_reset_by_status_read():
    _, device = ppu_machine()
    device.write(0x2000, 0x03, 1)
    device.write(0x2005, 0x7D, 2)        # x = 125
    status(device, 3)                    # resets the toggle: the next write is X again
    device.write(0x2005, 0x7D, 4)
    device.write(0x2005, 0x5E, 5)        # y = 94
    state = device.state()
    assert (state.scroll_x, state.scroll_y, state.ctrl & 3) == (125, 94, 3)


def test_vram_writes_mirroring_palette_and_buffered_reads():
    _, device = ppu_machine(make_state(mask=0, mirroring="horizontal"))
    def set_address(address, cycle):
        device.write(0x2006, address >> 8, cycle)
        device.write(0x2006, address & 0xFF, cycle + 1)
    set_address(0x2405, 10)
    device.write(0x2007, 0xAB, 12)       # horizontal mirroring: $2400 is $2000
    assert device.ciram[0x005] == 0xAB
    set_address(0x2C05, 20)
    device.write(0x2007, 0xCD, 22)       # $2C00 is $2800 = CIRAM page 1
    assert device.ciram[0x405] == 0xCD
    set_address(0x3F10, 30)
    device.write(0x2007, 0x21, 32)       # $3F10 mirrors $3F00
    assert device.palette[0] == 0x21
    set_address(0x2005, 40)
    device.read(0x2007, 42)              # returns the stale buffer, loads $2005 into it
    assert device.read(0x2007, 43) == 0xAB
    device.write(0x2000, 0x04, 50)       # increment 32
    set_address(0x2000, 51)
    device.write(0x2007, 1, 53)
    device.write(0x2007, 2, 54)
    assert device.ciram[0x000] == 1 and device.ciram[0x020] == 2


def test_oam_registers():
    _, device = ppu_machine()
    device.write(0x2003, 0xFE, 1)
    for cycle, value in enumerate((7, 8, 9), start=2):
        device.write(0x2004, value, cycle)   # $FE, $FF, then OAMADDR wraps to 0
    assert (device.oam[0xFE], device.oam[0xFF], device.oam[0]) == (7, 8, 9)
    device.write(0x2003, 0xFF, 9)
    assert device.read(0x2004, 10) == 8


def run_routine(source: str, state=None) -> tuple[Machine, PpuDevice, object]:
    machine, device = ppu_machine(state)
    program = machine.load(assemble_text(source))
    return machine, device, machine.call(program.origin)


def test_oam_dma_copies_page_and_stalls_513_or_514():
    source = """
        .org $c000
        {pad}
        lda #$03
        sta $4014
        rts
    """
    # The STA's write is its 4th cycle. No pad: LDA (2) then the write in cycle 2 + 3 = 5 (odd: 514).
    # A NOP first: cycle 7 (odd: 514).
    for pad, write_cycle in (("", 5), ("nop", 7)):
        machine, device = ppu_machine()
        for i in range(256):
            machine.poke(0x0300 + i, i ^ 0x5A)
        program = machine.load(assemble_text(source.format(pad=pad)))
        result = machine.call(program.origin)
        stall = 514 if write_cycle % 2 else 513
        base = (2 if pad else 0) + 2 + 4 + 6
        assert result.cycles == base + stall
        assert bytes(device.oam) == bytes(i ^ 0x5A for i in range(256))
    # An even write cycle needs an odd number of cycles before the LDA: BIT zp takes 3.
    machine, device = ppu_machine()
    program = machine.load(assemble_text(".org $c000\n bit $00\n lda #$03\n sta $4014\n rts\n"))
    result = machine.call(program.origin)
    # BIT zp 3 + LDA 2 = 5; STA writes in cycle 5 + 3 = 8 (even): 513.
    assert result.cycles == 3 + 2 + 4 + 513 + 6


POLL = """
        .org $c000
start:  bit $2002
vbl:    bit $2002           ; wait for vblank in frame 0 (rendering off: nothing else happens)
        bpl vbl
        lda #$1e
        sta $2001           ; rendering on from the vblank of frame 0
wait:   bit $2002           ; the classic loop: 7 cycles a turn
        bvc wait
first:  nop
clear:  bit $2002           ; wait for the pre-render line to clear the flag
        bvs clear
wait2:  bit $2002
        bvc wait2
second: rts
"""


def test_polling_loop_sees_the_hit_within_0_to_6_cycles():
    state = make_state(mask=0, cells={(0, 15, 16): 1}, sprite=(119, 1, 0, 128))
    machine, device = ppu_machine(state)
    program = machine.load(assemble_text(POLL))
    machine.run(program.origin, until="first")
    # The exiting BIT read its operand in its 4th cycle; BVC not taken (2) follows: read = clock - 3.
    read = machine.cycle - 3
    hit_dot = FULL_FRAME + 120 * 341 + 129          # frame 1 starts after the full frame 0 (even)
    first_visible = math.ceil(hit_dot / 3)
    assert 0 <= read - first_visible <= 6
    machine.run("clear", until="second")
    read2 = machine.cycle - 3
    hit_dot2 = FULL_FRAME + SHORT_FRAME + 120 * 341 + 129   # frame 1 is odd with rendering on
    assert 0 <= read2 - math.ceil(hit_dot2 / 3) <= 6


def test_polling_loop_pal():
    state = make_state(mask=0, cells={(0, 15, 16): 1}, sprite=(119, 1, 0, 128), video=PAL)
    machine, device = ppu_machine(state)
    program = machine.load(assemble_text(POLL))
    machine.run(program.origin, until="first")
    read = machine.cycle - 3
    hit_dot = 312 * 341 + 120 * 341 + 129           # PAL never skips a dot
    first_visible = math.ceil(hit_dot * 5 / 16)     # 3.2 dots per CPU cycle
    assert 0 <= read - first_visible <= 6


def test_polling_without_hit_hits_budget():
    import pytest

    from retro.errors import RunError
    machine, device = ppu_machine(make_state(mask=0x1E, cells={}, sprite=(119, 1, 0, 128)))
    program = machine.load(assemble_text(".org $c000\nwait: bit $2002\n bvc wait\n rts\n"))
    with pytest.raises(RunError):
        machine.call(program.origin, budget=200_000)
