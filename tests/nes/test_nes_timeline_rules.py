"""The rules of the NES vblank/NMI timeline, one test each, at the PPU device (docs/nes.md, "The
vblank and NMI timeline"). Each would fail if its rule changed by a dot; blargg's ppu_vbl_nmi and
vbl_nmi_timing ROMs (tests/nes/test_public_roms.py) are the same rules as the hardware shows them.

Worked by hand in the convention of retro.chips.ppu.clock: CPU cycle c reads and writes the PPU at
dot 3c (NTSC, PPU attached at cycle 0) and samples the NMI output at dot 3c + 1. With rendering off
every frame is 341 x 262 = 89342 dots (89342 mod 3 = 2), so frame k's vblank dot
V_k = 89342 k + 82182 falls on each of the three phases of a CPU cycle:
V_0 = 82182 = 3 x 27394, V_1 = 171524 = 3 x 57174 + 2, V_2 = 260866 = 3 x 86955 + 1.
The pre-render clear of frame 0 is at C = 261 x 341 + 1 = 89002 = 3 x 29667 + 1.
"""

from __future__ import annotations

from nes_build import make_state

from retro.chips.ppu.device import PpuDevice
from retro.machines.nes import build_nes, ppu_of

FRAME = 262 * 341
VBLANK = 241 * 341 + 1
CLEAR = 261 * 341 + 1
NMI_ON, NMI_OFF = 0x80, 0x00


def device(mask: int = 0) -> PpuDevice:
    return ppu_of(build_nes(make_state(mask=mask)))


def nmi_device() -> PpuDevice:
    ppu = device()
    ppu.write(0x2000, NMI_ON, 10)
    return ppu


def read_status(ppu: PpuDevice, cycle: int) -> int:
    return ppu.read(0x2002, cycle) & 0x80


def nmi_by(ppu: PpuDevice, cycle: int) -> bool:
    """Whether a poll in `cycle` takes an NMI."""
    return ppu.nmi_edge(cycle)


# ---- the $2002 read racing the vblank flag ---------------------------------------------------

def test_a_read_one_dot_before_the_vblank_dot_reads_clear_and_the_flag_is_never_set():
    v2 = 2 * FRAME + VBLANK                  # 260866 = 3 x 86955 + 1: cycle 86955 reads at V_2 - 1
    ppu = nmi_device()
    ppu.advance(2 * FRAME - 1)
    assert nmi_by(ppu, 2 * FRAME // 3)       # the NMIs of frames 0 and 1, out of the way
    assert read_status(ppu, (v2 - 1) // 3) == 0
    ppu.advance(v2 + 10)
    assert ppu.peek(0x2002) & 0x80 == 0      # never set this frame
    assert not nmi_by(ppu, v2 // 3 + 5)      # and no NMI


def test_a_read_two_dots_before_is_a_plain_read():
    v1 = FRAME + VBLANK                      # 3 x 57174 + 2: cycle 57174 reads at V_1 - 2
    ppu = nmi_device()
    ppu.advance(FRAME - 1)
    assert nmi_by(ppu, FRAME // 3)           # frame 0's NMI, taken
    assert read_status(ppu, 57174) == 0
    assert nmi_by(ppu, 57175)                # set at V_1 as usual, with its NMI
    assert ppu.peek(0x2002) & 0x80 == 0x80


def test_a_read_at_the_vblank_dot_reads_set_and_suppresses_the_nmi():
    ppu = nmi_device()
    assert read_status(ppu, VBLANK // 3) == 0x80   # cycle 27394 reads at V_0
    assert not nmi_by(ppu, VBLANK // 3 + 2)


def test_a_read_one_dot_after_reads_set_and_suppresses_the_nmi():
    ppu = nmi_device()
    ppu.advance(FRAME - 1)
    assert nmi_by(ppu, FRAME // 3)
    assert read_status(ppu, 57175) == 0x80   # dot 171525 = V_1 + 1
    assert not nmi_by(ppu, 57177)


def test_a_read_two_dots_after_leaves_the_nmi():
    ppu = nmi_device()
    ppu.advance(2 * FRAME - 1)
    assert nmi_by(ppu, 2 * FRAME // 3)       # frames 0 and 1 (one pending edge each, taken as one here)
    cycle = 86956                            # dot 260868 = V_2 + 2
    assert read_status(ppu, cycle) == 0x80
    assert nmi_by(ppu, cycle + 1)


# ---- when the CPU sees the NMI ---------------------------------------------------------------

def test_the_nmi_is_sampled_one_dot_after_the_dot_reads_see():
    # V_2 = 3 x 86955 + 1: cycle 86955 samples at dot 3 x 86955 + 1 = V_2, one dot before its reads
    # would see the flag (they see it from cycle 86956)
    ppu = nmi_device()
    ppu.advance(2 * FRAME - 1)
    nmi_by(ppu, 2 * FRAME // 3)
    v2 = 2 * FRAME + VBLANK
    assert not nmi_by(ppu, v2 // 3 - 1)
    assert nmi_by(ppu, v2 // 3)
    assert ppu.peek(0x2002) & 0x80 == 0x80


def test_enabling_the_nmi_one_dot_before_the_sample_of_the_clear_gives_no_nmi():
    # flag set, NMI enabled by a write at dot 3c: the NMI comes iff the clear (C = 3 x 29667 + 1) is
    # after the sample at 3c + 1
    ppu = device()
    ppu.write(0x2000, NMI_ON, 29666)         # sample 88999 < C: an NMI
    assert nmi_by(ppu, 29667)
    ppu = device()
    ppu.write(0x2000, NMI_ON, 29667)         # sample 89002 = C: the flag is gone, no NMI
    assert not nmi_by(ppu, 29668)


def test_disabling_the_nmi_two_dots_after_vblank_keeps_it_one_dot_after_loses_it():
    ppu = device()
    ppu.write(0x2000, NMI_ON, 10)
    ppu.write(0x2000, NMI_OFF, 27395)        # dot V_0 + 3: the sample at V_0 + 1 saw it
    assert nmi_by(ppu, 27396)
    ppu = device()
    ppu.write(0x2000, NMI_ON, 10)
    ppu.write(0x2000, NMI_OFF, 27394)        # dot V_0: disabled before any sample saw the output low
    assert not nmi_by(ppu, 27396)


# ---- the odd frame's skipped dot -------------------------------------------------------------

def test_the_odd_frame_skip_is_decided_with_2001_as_written_up_to_dot_338():
    decision = FRAME + 261 * 341 + 338       # frame 1 (odd), pre-render line, dot 338
    for written_at, short in ((decision - 1, True), (decision, False)):
        ppu = device(mask=0)
        ppu.advance(written_at)              # a write at this dot sees the events up to it
        ppu.write(0x2001, 0x08, 0)
        ppu.advance(decision + 1)              # before the frame ends (at 178683 or 178684)
        assert ppu.frame_length == FRAME - (1 if short else 0), written_at
