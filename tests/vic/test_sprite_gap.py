"""The sprite gap (issue 15, part 5): the VICE test programs spritegap2 and spritegap3, replayed.

Source: VICE-testprogs (github.com/libsidplayfp/VICE-testprogs, commit 221c7752), VICII/spritegap:
readme.txt, spritegap2.tas, spritegap3.tas and the dumps in dumps/ that the programs compare
against (real machines; the readme names them). What the programs do (read from their source):

- sprites n < m (every pair of 0..7) enabled, all at Y = $80; sprite n shows block $3FC0, sprite m
  block $3F80. spritegap3: byte 0 of row 20 is $40 in sprite n (pixel 1) and $80 in sprite m
  (pixel 0); spritegap2: rows 19 and 20 both. Everything else in the blocks is 0.
- for each pair, X runs so that sprite n is at X - 1 and sprite m at X, for X = 1 .. $1FF, one X
  per frame; the program reads $D01E in raster line $90 (clearing it) and again in line $A0, and
  when that value differs from the last one logged (3 at the start, never reset between pairs) it
  logs <sprites n+m> <X low> <X high> <value>.

The logs below are the dumps written out as MASK:X>VALUE (the bytes in order, 4 per entry). The
test replays the same loop on the model (one frame per X, $D01E latched between the two reads) and
compares the logs entry for entry: the expected values are the machines', not the model's.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from retro.chips.vic.constants import (
    NTSC,
    NTSC_OLD,
    PAL,
    REG_CONTROL1,
    REG_SPRITE_ENABLE,
    REG_SPRITE_X0,
    REG_SPRITE_X_MSB,
    REG_SPRITE_Y0,
    REGISTER_COUNT,
    SPRITE_BYTES,
    SPRITE_COUNT,
    Video,
)
from retro.chips.vic.model import VicState, frame_collisions, placement

# dumps/spritegap3-6569r1.bin (6569R1; the readme: spritegap3-pal-newvic.bin is the same)
SPRITEGAP3_6569R1 = """
03:163>00 03:17F>03 03:1F8>00 05:001>05 05:163>00 05:18F>05 05:1F8>00 09:001>09 09:163>00
09:19F>09 09:1F8>00 11:001>11 11:163>00 11:1AF>11 11:1F8>00 21:001>21 21:163>00 21:1BF>21
21:1F8>00 41:001>41 41:163>00 41:1CF>41 41:1F8>00 81:001>81 81:163>00 81:1DF>81 81:1F8>00
06:001>06 06:164>00 06:18F>06 06:1F8>00 0A:001>0A 0A:164>00 0A:19F>0A 0A:1F8>00 12:001>12
12:164>00 12:1AF>12 12:1F8>00 22:001>22 22:164>00 22:1BF>22 22:1F8>00 42:001>42 42:164>00
42:1CF>42 42:1F8>00 82:001>82 82:164>00 82:1DF>82 82:1F8>00 0C:001>0C 0C:164>00 0C:19F>0C
0C:1F8>00 14:001>14 14:164>00 14:1AF>14 14:1F8>00 24:001>24 24:164>00 24:1BF>24 24:1F8>00
44:001>44 44:164>00 44:1CF>44 44:1F8>00 84:001>84 84:164>00 84:1DF>84 84:1F8>00 18:001>18
18:164>00 18:1AF>18 18:1F8>00 28:001>28 28:164>00 28:1BF>28 28:1F8>00 48:001>48 48:164>00
48:1CF>48 48:1F8>00 88:001>88 88:164>00 88:1DF>88 88:1F8>00 30:001>30 30:164>00 30:1BF>30
30:1F8>00 50:001>50 50:164>00 50:1CF>50 50:1F8>00 90:001>90 90:164>00 90:1DF>90 90:1F8>00
60:001>60 60:164>00 60:1CF>60 60:1F8>00 A0:001>A0 A0:164>00 A0:1DF>A0 A0:1F8>00 C0:001>C0
C0:164>00 C0:1DF>C0 C0:1F8>00
"""

# dumps/spritegap3-6569.bin (a 6569R3): the same except the first X of the pairs (0, m), m >= 2
SPRITEGAP3_6569R3 = """
03:163>00 03:17F>03 03:1F8>00 05:002>05 05:163>00 05:18F>05 05:1F8>00 09:002>09 09:163>00
09:19F>09 09:1F8>00 11:002>11 11:163>00 11:1AF>11 11:1F8>00 21:002>21 21:163>00 21:1BF>21
21:1F8>00 41:002>41 41:163>00 41:1CF>41 41:1F8>00 81:002>81 81:163>00 81:1DF>81 81:1F8>00
06:001>06 06:164>00 06:18F>06 06:1F8>00 0A:001>0A 0A:164>00 0A:19F>0A 0A:1F8>00 12:001>12
12:164>00 12:1AF>12 12:1F8>00 22:001>22 22:164>00 22:1BF>22 22:1F8>00 42:001>42 42:164>00
42:1CF>42 42:1F8>00 82:001>82 82:164>00 82:1DF>82 82:1F8>00 0C:001>0C 0C:164>00 0C:19F>0C
0C:1F8>00 14:001>14 14:164>00 14:1AF>14 14:1F8>00 24:001>24 24:164>00 24:1BF>24 24:1F8>00
44:001>44 44:164>00 44:1CF>44 44:1F8>00 84:001>84 84:164>00 84:1DF>84 84:1F8>00 18:001>18
18:164>00 18:1AF>18 18:1F8>00 28:001>28 28:164>00 28:1BF>28 28:1F8>00 48:001>48 48:164>00
48:1CF>48 48:1F8>00 88:001>88 88:164>00 88:1DF>88 88:1F8>00 30:001>30 30:164>00 30:1BF>30
30:1F8>00 50:001>50 50:164>00 50:1CF>50 50:1F8>00 90:001>90 90:164>00 90:1DF>90 90:1F8>00
60:001>60 60:164>00 60:1CF>60 60:1F8>00 A0:001>A0 A0:164>00 A0:1DF>A0 A0:1F8>00 C0:001>C0
C0:164>00 C0:1DF>C0 C0:1F8>00
"""

# dumps/spritegap2-8565r2.bin: spritegap2.tas labels this reference "6569R1 / 8565R2"
SPRITEGAP2_6569R1_8565R2 = """
03:163>00 03:170>03 03:173>00 03:17F>03 03:1F8>00 05:001>05 05:163>00 05:170>05 05:183>00
05:18F>05 05:1F8>00 09:001>09 09:163>00 09:170>09 09:193>00 09:19F>09 09:1F8>00 11:001>11
11:163>00 11:170>11 11:1A3>00 11:1AF>11 11:1F8>00 21:001>21 21:163>00 21:170>21 21:1B3>00
21:1BF>21 21:1F8>00 41:001>41 41:163>00 41:170>41 41:1C3>00 41:1CF>41 41:1F8>00 81:001>81
81:163>00 81:170>81 81:1D3>00 81:1DF>81 81:1F8>00 06:001>06 06:173>00 06:180>06 06:183>00
06:18F>06 06:1F8>00 0A:001>0A 0A:173>00 0A:180>0A 0A:193>00 0A:19F>0A 0A:1F8>00 12:001>12
12:173>00 12:180>12 12:1A3>00 12:1AF>12 12:1F8>00 22:001>22 22:173>00 22:180>22 22:1B3>00
22:1BF>22 22:1F8>00 42:001>42 42:173>00 42:180>42 42:1C3>00 42:1CF>42 42:1F8>00 82:001>82
82:173>00 82:180>82 82:1D3>00 82:1DF>82 82:1F8>00 0C:001>0C 0C:183>00 0C:190>0C 0C:193>00
0C:19F>0C 0C:1F8>00 14:001>14 14:183>00 14:190>14 14:1A3>00 14:1AF>14 14:1F8>00 24:001>24
24:183>00 24:190>24 24:1B3>00 24:1BF>24 24:1F8>00 44:001>44 44:183>00 44:190>44 44:1C3>00
44:1CF>44 44:1F8>00 84:001>84 84:183>00 84:190>84 84:1D3>00 84:1DF>84 84:1F8>00 18:001>18
18:193>00 18:1A0>18 18:1A3>00 18:1AF>18 18:1F8>00 28:001>28 28:193>00 28:1A0>28 28:1B3>00
28:1BF>28 28:1F8>00 48:001>48 48:193>00 48:1A0>48 48:1C3>00 48:1CF>48 48:1F8>00 88:001>88
88:193>00 88:1A0>88 88:1D3>00 88:1DF>88 88:1F8>00 30:001>30 30:1A3>00 30:1B0>30 30:1B3>00
30:1BF>30 30:1F8>00 50:001>50 50:1A3>00 50:1B0>50 50:1C3>00 50:1CF>50 50:1F8>00 90:001>90
90:1A3>00 90:1B0>90 90:1D3>00 90:1DF>90 90:1F8>00 60:001>60 60:1B3>00 60:1C0>60 60:1C3>00
60:1CF>60 60:1F8>00 A0:001>A0 A0:1B3>00 A0:1C0>A0 A0:1D3>00 A0:1DF>A0 A0:1F8>00 C0:001>C0
C0:1C3>00 C0:1D0>C0 C0:1D3>00 C0:1DF>C0 C0:1F8>00
"""

# dumps/spritegap3-6567r8.bin (the same bytes as spritegap3-ntsc-c128.bin)
SPRITEGAP3_6567R8 = """
03:16B>00 03:187>03 03:188>00 03:189>03 05:001>05 05:16B>00 05:18F>05 09:001>09 09:16B>00
09:19F>09 11:001>11 11:16B>00 11:1AF>11 21:001>21 21:16B>00 21:1BF>21 41:001>41 41:16B>00
41:1CF>41 81:001>81 81:16B>00 81:1DF>81 06:001>06 06:16C>00 06:18F>06 0A:001>0A 0A:16C>00
0A:19F>0A 12:001>12 12:16C>00 12:1AF>12 22:001>22 22:16C>00 22:1BF>22 42:001>42 42:16C>00
42:1CF>42 82:001>82 82:16C>00 82:1DF>82 0C:001>0C 0C:16C>00 0C:19F>0C 14:001>14 14:16C>00
14:1AF>14 24:001>24 24:16C>00 24:1BF>24 44:001>44 44:16C>00 44:1CF>44 84:001>84 84:16C>00
84:1DF>84 18:001>18 18:16C>00 18:1AF>18 28:001>28 28:16C>00 28:1BF>28 48:001>48 48:16C>00
48:1CF>48 88:001>88 88:16C>00 88:1DF>88 30:001>30 30:16C>00 30:1BF>30 50:001>50 50:16C>00
50:1CF>50 90:001>90 90:16C>00 90:1DF>90 60:001>60 60:16C>00 60:1CF>60 A0:001>A0 A0:16C>00
A0:1DF>A0 C0:001>C0 C0:16C>00 C0:1DF>C0
"""

# dumps/spritegap2-6567r8.bin (the same bytes as spritegap2-ntsc-c128.bin)
SPRITEGAP2_6567R8 = """
03:16B>00 03:178>03 03:17B>00 03:187>03 03:188>00 03:189>03 05:001>05 05:16B>00 05:178>05
05:188>00 05:18F>05 09:001>09 09:16B>00 09:178>09 09:188>00 09:189>09 09:193>00 09:19F>09
11:001>11 11:16B>00 11:178>11 11:188>00 11:189>11 11:1A3>00 11:1AF>11 21:001>21 21:16B>00
21:178>21 21:188>00 21:189>21 21:1B3>00 21:1BF>21 41:001>41 41:16B>00 41:178>41 41:188>00
41:189>41 41:1C3>00 41:1CF>41 81:001>81 81:16B>00 81:178>81 81:188>00 81:189>81 81:1D3>00
81:1DF>81 06:001>06 06:17B>00 06:18F>06 0A:001>0A 0A:17B>00 0A:189>0A 0A:193>00 0A:19F>0A
12:001>12 12:17B>00 12:189>12 12:1A3>00 12:1AF>12 22:001>22 22:17B>00 22:189>22 22:1B3>00
22:1BF>22 42:001>42 42:17B>00 42:189>42 42:1C3>00 42:1CF>42 82:001>82 82:17B>00 82:189>82
82:1D3>00 82:1DF>82 0C:001>0C 0C:188>00 0C:190>0C 0C:193>00 0C:19F>0C 14:001>14 14:188>00
14:190>14 14:1A3>00 14:1AF>14 24:001>24 24:188>00 24:190>24 24:1B3>00 24:1BF>24 44:001>44
44:188>00 44:190>44 44:1C3>00 44:1CF>44 84:001>84 84:188>00 84:190>84 84:1D3>00 84:1DF>84
18:001>18 18:188>00 18:189>18 18:193>00 18:1A0>18 18:1A3>00 18:1AF>18 28:001>28 28:188>00
28:189>28 28:193>00 28:1A0>28 28:1B3>00 28:1BF>28 48:001>48 48:188>00 48:189>48 48:193>00
48:1A0>48 48:1C3>00 48:1CF>48 88:001>88 88:188>00 88:189>88 88:193>00 88:1A0>88 88:1D3>00
88:1DF>88 30:001>30 30:188>00 30:189>30 30:1A3>00 30:1B0>30 30:1B3>00 30:1BF>30 50:001>50
50:188>00 50:189>50 50:1A3>00 50:1B0>50 50:1C3>00 50:1CF>50 90:001>90 90:188>00 90:189>90
90:1A3>00 90:1B0>90 90:1D3>00 90:1DF>90 60:001>60 60:188>00 60:189>60 60:1B3>00 60:1C0>60
60:1C3>00 60:1CF>60 A0:001>A0 A0:188>00 A0:189>A0 A0:1B3>00 A0:1C0>A0 A0:1D3>00 A0:1DF>A0
C0:001>C0 C0:188>00 C0:189>C0 C0:1C3>00 C0:1D0>C0 C0:1D3>00 C0:1DF>C0
"""

SPRITE_Y = 0x80  # every sprite
CLEAR_LINE, TEST_LINE = 0x90, 0xA0  # the program reads $D01E in these lines
LOG_START = 0x03  # the value the log starts from ($F8)
SCREEN_ON = 0x1B  # $D011 after the KERNAL's VIC init
ROW_BYTE0 = {3: (20,), 2: (19, 20)}  # program -> rows whose byte 0 is set
LOWER_PIXEL1, UPPER_PIXEL0 = 0x40, 0x80  # the byte in sprite n's and in sprite m's rows
LAST_X = 0x1FF


def parse_log(text: str) -> list[tuple[int, int, int]]:
    entries = []
    for token in text.split():
        mask, rest = token.split(":")
        x, value = rest.split(">")
        entries.append((int(mask, 16), int(x, 16), int(value, 16)))
    return entries


def sprite_block(rows: tuple[int, ...], byte0: int) -> bytes:
    block = bytearray(SPRITE_BYTES)
    for row in rows:
        block[3 * row] = byte0
    return bytes(block)


def pair_state(video: Video, program: int, n: int, m: int, x: int) -> VicState:
    """Sprite n at X - 1, sprite m at X ($D010 as the program writes it), both at Y $80."""
    registers = bytearray(REGISTER_COUNT)
    registers[REG_CONTROL1] = SCREEN_ON
    registers[REG_SPRITE_ENABLE] = 1 << n | 1 << m
    for sprite, at in ((n, x - 1), (m, x)):
        registers[REG_SPRITE_X0 + 2 * sprite] = at & 0xFF
        registers[REG_SPRITE_Y0 + 2 * sprite] = SPRITE_Y
        registers[REG_SPRITE_X_MSB] |= (at >> 8) << sprite
    data = [bytes(SPRITE_BYTES)] * SPRITE_COUNT
    data[n] = sprite_block(ROW_BYTE0[program], LOWER_PIXEL1)
    data[m] = sprite_block(ROW_BYTE0[program], UPPER_PIXEL0)
    return VicState(video, bytes(registers), tuple(data))


def d01e_between_reads(state: VicState) -> int:
    """$D01E as read in line $A0 after a read in line $90 cleared it."""
    events = frame_collisions(state)
    cpl = state.video.cycles_per_line
    window = (events.ss_times >= CLEAR_LINE * cpl) & (events.ss_times < TEST_LINE * cpl)
    return int(np.bitwise_or.reduce(events.ss_bits[window])) if window.any() else 0


@lru_cache(maxsize=None)
def replay(video: Video, program: int) -> tuple[tuple[int, int, int], ...]:
    log, last = [], LOG_START
    for n in range(SPRITE_COUNT - 1):
        for m in range(n + 1, SPRITE_COUNT):
            for x in range(1, LAST_X + 1):
                value = d01e_between_reads(pair_state(video, program, n, m, x))
                if value != last:
                    log.append((1 << n | 1 << m, x, value))
                    last = value
    return tuple(log)


def differences(got, expected) -> list[str]:
    shown = [f"{m:02X}:{x:03X}>{v:02X}" for m, x, v in got]
    wanted = [f"{m:02X}:{x:03X}>{v:02X}" for m, x, v in expected]
    return [f"model {a} / machine {b}" for a, b in zip(shown, wanted) if a != b] + (
        [f"{len(shown)} entries, the machine {len(wanted)}"] if len(shown) != len(wanted) else [])


@pytest.mark.parametrize("video, program, dump", [
    (PAL, 3, SPRITEGAP3_6569R1),
    (PAL, 2, SPRITEGAP2_6569R1_8565R2),
    (NTSC, 3, SPRITEGAP3_6567R8),
    (NTSC, 2, SPRITEGAP2_6567R8),
], ids=["spritegap3-6569r1", "spritegap2-6569r1-8565r2", "spritegap3-6567r8", "spritegap2-6567r8"])
def test_spritegap_logs_match_the_machines(video, program, dump):
    assert differences(replay(video, program), parse_log(dump)) == []


def test_spritegap3_6569r3_differs_only_right_after_a_pair_left_sprite_0_at_x_1fe():
    # The 6569R3 machine does not see the pairs (0, m), m >= 2, collide at X 1 (sprite 0 at X 0),
    # only from X 2 on: the frame before had sprite 0 at X $1FE, where it never shows. The model
    # takes every frame as steady (as if sprite 0 had been at X 0 before) and gives what the 6569R1
    # and the "new PAL" machine dumped.
    model = replay(PAL, 3)
    r3 = parse_log(SPRITEGAP3_6569R3)
    assert len(model) == len(r3)
    differ = [(a, b) for a, b in zip(model, r3) if a != b]
    assert differ and all(a[0] & 1 and a[0] != 0x03 and (a[1], b[1]) == (1, 2) and a[2] == b[2] for a, b in differ)


def test_readme_example_pairs_0_1_and_0_2():
    # readme.txt: "Sprite#0 and sprite#1 stop colliding at 0x0163, they collide again at 0x17f and
    # stop colliding at 0x1f8. Sprite#0 and Sprite#2 collide at 0x001, they stop colliding at 0x163
    # and collide again at 0x18f."
    def collide(n, m, x):
        return d01e_between_reads(pair_state(PAL, 3, n, m, x)) == 1 << n | 1 << m

    assert collide(0, 1, 0x162) and not collide(0, 1, 0x163)
    assert not collide(0, 1, 0x17E) and collide(0, 1, 0x17F)
    assert collide(0, 1, 0x1F7) and not collide(0, 1, 0x1F8)
    assert collide(0, 2, 0x001) and collide(0, 2, 0x162) and not collide(0, 2, 0x163)
    assert not collide(0, 2, 0x18E) and collide(0, 2, 0x18F)


def test_a_sprite_whose_x_falls_in_its_own_halt_never_shows():
    # spritegap2 (both rows 19 and 20 set): the pair (0, 1) collides at X $170-$172 but not at
    # $173-$17E, where sprite 1 (at X) is halted; nor at $163-$16F, where sprite 0 (at X - 1) is.
    assert placement(pair_state(PAL, 2, 0, 1, 0x173), 1) is None
    assert placement(pair_state(PAL, 2, 0, 1, 0x17F), 1) is not None
    assert placement(pair_state(PAL, 2, 0, 1, 0x164), 0) is None  # sprite 0 at $163
    assert placement(pair_state(NTSC, 2, 0, 1, 0x16C), 0) is None  # sprite 0 at $16B


def test_the_6567r56a_draws_each_x_once_so_a_halted_x_never_comes_back():
    # No real-hardware dump of a 6567R56A: worked by hand from the rule above, with Bauer's 6567R56A
    # diagram (64 cycles, 512 X coordinates, 8 a cycle from $19C in cycle 1; sprite 1's fetch in
    # cycle 59 + 2 = 61). The sequencer runs 4 X behind: cycle c draws X $198 + 8(c - 1) (mod $200),
    # cycle 61 X $178-$17F. Sprite 1 halts at its pixel 3, X $17B, and may start again from pixel 7
    # of cycle 62, X $187: at X $17B-$186 it never shows. The 6567R8 draws $180-$187 a second time
    # in cycle 63, after the halt, so there sprite 1 at $180-$186 does show (the spritegap dumps).
    for x in (0x17B, 0x180, 0x186):
        assert placement(pair_state(NTSC_OLD, 2, 0, 1, x), 1) is None, hex(x)
    for x in (0x17A, 0x187):
        assert placement(pair_state(NTSC_OLD, 2, 0, 1, x), 1) is not None, hex(x)
    assert placement(pair_state(NTSC, 2, 0, 1, 0x17B), 1) is None
    assert placement(pair_state(NTSC, 2, 0, 1, 0x180), 1) is not None


def test_the_last_row_goes_when_x_comes_after_the_display_check():
    # spritegap3 (row 20 only): pairs (n >= 1, m) stop colliding at X $164 (PAL) / $16C (NTSC):
    # sprite m's row 20 is not shown, while rows 0-19 still are.
    for video, x in ((PAL, 0x164), (NTSC, 0x16C)):
        before = placement(pair_state(video, 2, 1, 2, x - 1), 2)
        after = placement(pair_state(video, 2, 1, 2, x), 2)
        assert set(before.rows.tolist()) == {19, 20}
        assert set(after.rows.tolist()) == {19}


def test_the_row_being_shown_at_the_halt_repeats_its_last_pixel_then_stops():
    # Not measured by the programs above (their pixel before the halt is transparent): VICE x64sc's
    # rule (viciisc/vicii-draw-cycle.c: the shift register stops at pixel 3 of the sprite's p-access
    # cycle, the sprite is switched off at pixel 2 of the next cycle). Worked by hand for PAL sprite 0
    # at X $150 with every pixel set: the halt comes at X $163 (cycle 58 draws X $160-$167), so
    # pixels 0-18 are at X $150-$162, pixel 18 is repeated at X $163-$169 (7 positions), and pixels
    # 19-23 are never drawn.
    registers = bytearray(REGISTER_COUNT)
    registers[REG_SPRITE_ENABLE] = 1
    registers[REG_SPRITE_X0] = 0x50
    registers[REG_SPRITE_X_MSB] = 1
    registers[REG_SPRITE_Y0] = SPRITE_Y
    data = (b"\xff" * SPRITE_BYTES,) + (bytes(SPRITE_BYTES),) * (SPRITE_COUNT - 1)
    place = placement(VicState(PAL, bytes(registers), data), 0)
    one_row = place.rows == 10
    assert sorted(place.xs[one_row].tolist()) == list(range(0x150, 0x16A))
    assert place.cols[one_row][place.xs[one_row] >= 0x163].tolist() == [18] * 7
