"""Which cycles sprite DMA takes from the CPU, per chip (issue 15, parts 1 and 2 revisited).

The fact under test is one number per chip, Video.sprite0_fetch_cycle: sprite n's p-access and
first s-access fall in cycle sprite0_fetch_cycle + 2n, its other two s-accesses in the next cycle,
and BA goes low BA_LEAD (3) cycles before, so a sprite's BA window is five cycles long.

Sources (docs/vic.md, "Sprite DMA cycle"):
- VICE-testprogs (github.com/libsidplayfp/VICE-testprogs, commit 221c7752), VICII/spritesteal
  (Hannu Nuotio, 2010): core.asm and README.txt. The program enables sprites at Y = 9 (then Y = 10)
  with $D015 = 0, 1, 2, 4, ... $80, $FF, and from a stable raster interrupt reads a CIA timer 63
  times, the k-th read nominally in cycle 51 + k of line 9 (its cycles counted from 0 at the
  raster IRQ: Bauer's cycle 1 is its cycle 0); every cycle before each read is a read cycle, so a
  BA-low cycle costs the CPU that cycle. It compares the timer values with values it computes from
  a table of the cycles in which each sprite's DMA holds BA low, and the README records that a
  real 6569R3 (spritesteal.prg) and real 6567R8, 8562 and 8564 machines (spritesteal_ntsc.prg)
  match. Read from the table (in its numbering; the window of sprite n is 2n later):
    6569 (63 cycles):     sprite 0 in cycles 54-58 -> Bauer's cycles 55-59, s-accesses 58-59;
    6567R8 (65 cycles):   sprite 0 in cycles 55-59 -> cycles 56-60, s-accesses 59-60;
    6567R56A (64 cycles): sprite 0 in cycles 55-59 -> cycles 56-60, s-accesses 59-60
  (spritesteal_ntscold.prg: the README records no real 6567R56A; the table agrees with Bauer's
  6567R56A diagram and VICE's cycle_tab_ntsc_old). The test replays the 63 reads on the emulator and
  expects each read in the cycle the table gives: the k-th cycle, from cycle 51 on, that no enabled
  sprite's window holds. These programs' source is not copied: the replay is a NOP run from line 9
  cycle 1 and one LDA abs.
- Bauer's 6567R8 diagram puts sprite 0's fetch in cycle 60 (BA low 57-61); the real 6567R8s of
  spritesteal disagree, and so do the 6567R8 spritegap dumps (tests/vic/test_sprite_gap.py).
"""

from __future__ import annotations

import pytest

from retro.chips.vic.constants import (
    NTSC,
    NTSC_OLD,
    PAL,
    REG_CONTROL1,
    REG_SPRITE_ENABLE,
    REG_SPRITE_Y0,
    REGISTER_COUNT,
    SPRITE_BYTES,
    SPRITE_COUNT,
    VIC_BASE,
    VIC_LAST,
)
from retro.chips.vic.device import VicDevice
from retro.chips.vic.model import VicState
from retro.cpu.machine import Machine

DEN_OFF = 0x0B  # no Bad Lines: only sprite DMA takes the bus
ENTRY = 0xC000
NOP, BIT_ZP, LDA_ABS, STA_ABS, RTS = 0xEA, 0x24, 0xAD, 0x8D, 0x60
TARGET = (0x00, 0x04)  # $0400, plain RAM

# spritesteal's table, in its numbering (0 = Bauer's cycle 1): the first cycle of sprite 0's BA
# window; sprite n's is 2n later, five cycles long (3 with BA low before the fetch, 2 stolen).
SPRITESTEAL_FIRST_LOW = {PAL: 54, NTSC: 55, NTSC_OLD: 55}
WINDOW = 5
FIRST_READ = 51  # "timer reads, first on line 9 cycle 51"
READS = 63
STEAL_LINE = 9  # sprites at Y = 9 fetch in lines 9-29: DMA in line 9 (and line 10) of the reads
MASKS = (0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x20, 0x40, 0x80, 0xFF)


def sprites_at(video, y: int, enabled: int, control1: int = DEN_OFF) -> VicState:
    registers = bytearray(REGISTER_COUNT)
    registers[REG_CONTROL1] = control1
    registers[REG_SPRITE_ENABLE] = enabled
    for n in range(SPRITE_COUNT):
        registers[REG_SPRITE_Y0 + 2 * n] = y
    return VicState(video, bytes(registers), (bytes(SPRITE_BYTES),) * SPRITE_COUNT)


def run_from(video, state: VicState, code: bytes, line: int, cycle: int = 1):
    machine = Machine()
    machine.poke(ENTRY, code)
    machine.attach(VicDevice.at_beam(state, machine.cycle, line, cycle), VIC_BASE, VIC_LAST)
    return machine.call(ENTRY, trace=True)


def read_cycle(video, state: VicState, nominal: int) -> int:
    """Run read cycles from line 9 cycle 1 so that an LDA abs reads in 0-based cycle `nominal` of the
    line when nothing stalls; return the 0-based cycle (from line 9 cycle 1) it really reads in."""
    before = nominal - 3  # the LDA's opcode and two operand fetches come first
    bit = before % 2  # an odd count starts with BIT zp (3 cycles), the rest are NOPs (2)
    prefix = bytes([BIT_ZP, 0xEA]) * bit + bytes([NOP]) * ((before - 3 * bit) // 2)
    result = run_from(video, state, prefix + bytes([LDA_ABS, *TARGET, RTS]), STEAL_LINE)
    through_lda = result.trace[:-1]  # every entry but the RTS
    assert through_lda[-1].mnemonic == "LDA"
    return sum(entry.cycles for entry in through_lda) - 1


def spritesteal_reads(video, y: int, enabled: int) -> list[int]:
    """The cycles of the 63 reads as spritesteal's table gives them (0-based from line 9 cycle 1)."""
    held = set()
    if y == STEAL_LINE:
        for n in range(SPRITE_COUNT):
            if enabled >> n & 1:
                for line in (0, 1):  # the DMA of line 9 and of line 10
                    first = line * video.cycles_per_line + SPRITESTEAL_FIRST_LOW[video] + 2 * n
                    held.update(range(first, first + WINDOW))
    free = (t for t in range(FIRST_READ, FIRST_READ + 3 * video.cycles_per_line) if t not in held)
    return [next(free) for _ in range(READS)]


@pytest.mark.parametrize("video", [PAL, NTSC, NTSC_OLD], ids=lambda v: v.chip)
@pytest.mark.parametrize("y", [STEAL_LINE, STEAL_LINE + 1])
@pytest.mark.parametrize("enabled", MASKS, ids=lambda m: f"d015={m:02x}")
def test_spritesteal_reads_fall_where_the_real_machines_put_them(video, y, enabled):
    state = sprites_at(video, y, enabled)
    measured = [read_cycle(video, state, FIRST_READ + k) for k in range(READS)]
    assert measured == spritesteal_reads(video, y, enabled)


def test_spritesteal_figures_by_hand():
    # Sprite 0 alone on the 6567R8: reads nominally at 0-based cycles 51-54 are not held; the one
    # nominally at 55 (Bauer's cycle 56, the first with BA low) waits until cycle 60 (Bauer's 61),
    # five cycles, and so does every later one (64 -> 69). With sprite 0 in cycle 60 (Bauer's
    # diagram) the read at 55 would not wait and the one at 56 would wait to 61.
    reads = spritesteal_reads(NTSC, STEAL_LINE, 0x01)
    assert reads[:6] == [51, 52, 53, 54, 60, 61]
    assert reads[13] == 69
    # All eight on the 6567R8: BA low from 0-based 55 through 55 + 14 + 4 = 73 (0-based cycle 8 of
    # line 10, Bauer's cycle 9);
    # the read nominally at 55 comes at 74, 19 cycles later.
    assert spritesteal_reads(NTSC, STEAL_LINE, 0xFF)[4] == 74
    # Sprite 7 alone on the 6569: its window is 0-based 54 + 14 = 68 .. 72, 0-based cycles 5-9 of
    # line 10 (Bauer's 6-10, stolen 9-10): reads 0-16 at 51-67, read 17 waits to 73.
    reads = spritesteal_reads(PAL, STEAL_LINE, 0x80)
    assert reads[16:19] == [67, 73, 74]


# The BA lead: writes go on while BA is low, so the cycles lost depend on the instruction.
@pytest.mark.parametrize("video, start, opcode, cycles, stolen", [
    # 6567R8, sprite 0 fetching in line 100: BA low in cycles 56-60, stolen 59-60. STA abs in cycles
    # 53-56 writes in 56 (BA low: it goes on); the NOP's opcode fetch in 57 waits to 61: 4 lost.
    # Then NOP 61-62, RTS 63-68 (BA high from 61): 4 + 4 + 2 + 6 = 16 cycles. (With sprite 0 in
    # cycle 60, as Bauer's diagram has it, BA would go low in 57 and 5 would be lost.)
    (NTSC, 53, STA_ABS, 16, 4),
    # LDA abs in the same cycles reads in 56: it waits to 61, all 5 lost: 17 cycles.
    (NTSC, 53, LDA_ABS, 17, 5),
    # The 6567R56A: the same cycles (sprite 0 in 59-60).
    (NTSC_OLD, 53, STA_ABS, 16, 4),
    (NTSC_OLD, 53, LDA_ABS, 17, 5),
    # The 6569: BA low in 55-59; STA abs in 52-55 writes in 55: 4 lost.
    (PAL, 52, STA_ABS, 16, 4),
    (PAL, 52, LDA_ABS, 17, 5),
])
def test_a_write_in_the_first_ba_low_cycle_goes_on(video, start, opcode, cycles, stolen):
    state = sprites_at(video, 100, 0x01)
    result = run_from(video, state, bytes([opcode, *TARGET, NOP, RTS]), 100, start)
    assert (result.cycles, result.stolen) == (cycles, stolen)


@pytest.mark.parametrize("video, stalled_nop", [
    # NOPs from cycle 1 of line 100, sprite 0 fetching there: NOP k runs in cycles 2k+1, 2k+2.
    # 6567R8 and 6567R56A: BA low from 56, the dummy read of NOP 27 (cycles 55-56) waits 5.
    (NTSC, 27),
    (NTSC_OLD, 27),
    # 6569: BA low from 55, the opcode fetch of NOP 27 (55-56) waits 5.
    (PAL, 27),
])
def test_which_instruction_sprite_0_stops(video, stalled_nop):
    state = sprites_at(video, 100, 0x01)
    result = run_from(video, state, bytes([NOP]) * 40 + bytes([RTS]), 100)
    assert [k for k, entry in enumerate(result.trace) if entry.stolen] == [stalled_nop]
    assert result.trace[stalled_nop].stolen == 5


# ---- the 6567R56A through the whole chain (64 cycles a line, 262 lines) ---------------------------
# Worked by hand from Bauer's 6567R56A diagram (docs/vic.md): Bad Line BA low 12-54, sprite n's
# s-accesses in 59+2n and 60+2n, raster IRQ in cycle 1 (cycle 2 in line 0), X $19C in cycle 1.

LDX_IMM, INX, CMP_IMM, BNE, BEQ, CLI, LDA_IMM, RTI = 0xA2, 0xE8, 0xC9, 0xD0, 0xF0, 0x58, 0xA9, 0x40
DEN_ON = 0x1B  # Bad Lines on lines $33, $3B, ...


def count_to_next_line(video, control1: int, line: int, enabled: int) -> tuple[int, int, int]:
    # LDX #0; loop: INX (2), LDA $D012 (4, reads in its 4th cycle), CMP #line+1 (2), BNE loop (3
    # taken); RTS. Iteration k reads at offset 7 + 11k; the call takes (last read) + 11 cycles.
    code = bytes([LDX_IMM, 0, INX, LDA_ABS, 0x12, 0xD0, CMP_IMM, line + 1, BNE, 0xF8, RTS])
    result = run_from(video, sprites_at(video, line, enabled, control1), code, line)
    return result.x, result.cycles, result.stolen


@pytest.mark.parametrize("video, control1, line, enabled, expected", [
    # No DMA: reads at 7, 18, ..., 73; the first at offset >= 64 (line 101) is 73: X = 7.
    (NTSC_OLD, DEN_OFF, 100, 0x00, (7, 84, 0)),
    # Sprite 0: BA low 56-60 (offsets 55-59). Iteration 4 (offsets 46-56): its BNE reads its operand
    # at 55 and waits to 60; iteration 5 starts at 62 and reads at 67 >= 64: X = 6, 67 + 11.
    (NTSC_OLD, DEN_OFF, 100, 0x01, (6, 78, 5)),
    # Eight sprites: BA low from 56 through sprite 7's s-accesses in cycles 59 + 14 = 73 and 74 of
    # line 100, i.e. 101:9-10 (offsets 72-73): offsets 55-73. The same BNE waits 19 (to 74),
    # iteration 5 starts at 76 and reads at 81: X = 6, 81 + 11.
    (NTSC_OLD, DEN_OFF, 100, 0xFF, (6, 92, 19)),
    # The 6567R8, eight sprites: sprite 7's s-accesses in 73 and 74 = 101:8-9 (offsets 72-73): BA
    # low in offsets 55-73 again, the same 19 and X = 6.
    (NTSC, DEN_OFF, 100, 0xFF, (6, 92, 19)),
    # Bad Line $33 (YSCROLL 3) on the 6567R56A: iteration 0's BNE reads its operand at offset 11
    # (cycle 12, BA low) and waits to 54: 43 lost; iteration 1 reads at 61 (line $33), iteration
    # 2 at 72 >= 64: X = 3, 72 + 11.
    (NTSC_OLD, DEN_ON, 0x33, 0x00, (3, 83, 43)),
])
def test_loop_counted_to_the_next_line(video, control1, line, enabled, expected):
    assert count_to_next_line(video, control1, line, enabled) == expected


IRQ_HANDLER = 0xC100


def handler_reached(video, line: int, compare: int) -> tuple[int, int]:
    """CLI and NOPs from `line` cycle 1 with the raster IRQ at `compare`: (line, cycle) of the
    handler's first cycle."""
    registers = bytearray(REGISTER_COUNT)
    registers[REG_CONTROL1] = DEN_OFF | (compare >> 8) << 7
    registers[0x12], registers[0x1A] = compare & 0xFF, 0x01  # $D012 compare, $D01A raster IRQ on
    state = VicState(video, bytes(registers), (bytes(SPRITE_BYTES),) * SPRITE_COUNT)
    machine = Machine()
    machine.poke(ENTRY, bytes([CLI]) + bytes([NOP]) * 80 + bytes([RTS]))
    machine.poke(IRQ_HANDLER, bytes([LDA_IMM, 0xFF, STA_ABS, 0x19, 0xD0, RTI]))
    machine.poke(0xFFFE, [IRQ_HANDLER & 0xFF, IRQ_HANDLER >> 8])
    machine.attach(VicDevice.at_beam(state, machine.cycle, line, 1), VIC_BASE, VIC_LAST)
    trace = machine.call(ENTRY, p=0x20, trace=True).trace
    names = [entry.mnemonic for entry in trace]
    offset = sum(entry.cycles for entry in trace[:names.index("IRQ") + 1])
    return (line + offset // video.cycles_per_line) % video.lines, offset % video.cycles_per_line + 1


@pytest.mark.parametrize("video, line, compare, expected", [
    # 6567R56A: CLI 99:1-2, NOPs from 3; 64 is even, so a NOP runs in 99:63-64 and the next in
    # 100:1-2: it polls in its first cycle, 100:1, where the IRQ comes: taken, sequence 3-9, the
    # handler in cycle 10.
    (NTSC_OLD, 99, 100, (100, 10)),
    # 6567R8: the NOP in 99:65 / 100:1 polls at 65, too early; the one in 100:2-3 polls at 2:
    # sequence 4-10, handler in 11 (the 6569, 63 cycles, the same: 99:63 / 100:1).
    (NTSC, 99, 100, (100, 11)),
    (PAL, 99, 100, (100, 11)),
    # Line 0 of the 6567R56A (from line 261, its last): the IRQ comes in cycle 2; the NOP in 0:1-2
    # polls at 1, too early; the one in 0:3-4 polls at 3: sequence 5-11, handler in 12.
    (NTSC_OLD, 261, 0, (0, 12)),
])
def test_raster_irq_reaches_the_handler(video, line, compare, expected):
    assert handler_reached(video, line, compare) == expected


def test_first_read_that_sees_a_collision_bit_on_the_6567r56a():
    # Sprites 0 and 2 at (100, 100), solid: first common pixel line 101, X 100, latched in cycle
    # 1 + (((100 - $19C) mod $200) + 4) // 8 = 1 + 204 // 8 = 26 of line 101: offset 64 + 25 = 89
    # from line 100 cycle 1; a read at offset > 89 sees it. LDA $D01E (4) / BEQ (3) reads at 3 + 7k.
    # BA low 56-60 (sprite 0) and 60-64 (sprite 2): offsets 55-63. Iteration 7's BEQ (53-55) stops
    # in its dummy read at 55 and waits 9, to 64; from 65 the reads fall at 68, 75, 82, 89 (not
    # yet) and 96: %101, after 96 + 1 + 2 (BEQ not taken) + 6 (RTS) = 105 cycles.
    registers = bytearray(REGISTER_COUNT)
    registers[REG_CONTROL1], registers[REG_SPRITE_ENABLE] = DEN_OFF, 0b101
    for n in (0, 2):
        registers[2 * n], registers[REG_SPRITE_Y0 + 2 * n] = 100, 100
    state = VicState(NTSC_OLD, bytes(registers), (b"\xff" * SPRITE_BYTES,) * SPRITE_COUNT)
    result = run_from(NTSC_OLD, state, bytes([LDA_ABS, 0x1E, 0xD0, BEQ, 0xFB, RTS]), 100)
    assert (result.a, result.cycles, result.stolen) == (0b101, 105, 9)


def test_a_scene_says_ntsc_old():
    # The scene format's video key takes every chip of constants.VIDEOS; "ntsc-old" is the
    # 6567R56A, with its 262 lines and 64 cycles for cpu.start_line / start_cycle.
    from vic_scenes import scene, sprite

    from retro.chips.vic.model import run_frames
    from retro.scenes.vic import parse

    doc = {"chip": "vic-ii", "video": "ntsc-old", "registers": {"$d011": DEN_OFF},
           "sprite": [{"index": 0, "x": 100, "y": 100, "rows": ["#" * 24] * 21},
                      {"index": 2, "x": 100, "y": 100, "rows": ["#" * 24] * 21}],
           "cpu": {"start_line": 261, "start_cycle": 64}}
    parsed = parse(doc, "old.toml")
    assert parsed.state.video is NTSC_OLD
    assert (parsed.start_line, parsed.start_cycle) == (261, 64)
    assert run_frames(parsed.state).d01e == 0b101
    # The same sprites, the same poll as above, from the scene's state.
    result = run_from(NTSC_OLD, parsed.state, bytes([LDA_ABS, 0x1E, 0xD0, BEQ, 0xFB, RTS]), 100)
    assert (result.a, result.cycles, result.stolen) == (0b101, 105, 9)
    # Two overlapping sprites through the test helpers' scene builder.
    assert run_frames(scene(sprite(0, 100, 100), sprite(1, 110, 110), video="ntsc-old").state).d01e == 0b11
