"""A $D01D (X expansion) or $D01C (multicolour) write while a sprite row is being shown
(retro/chips/vic/device.py `_switch_rows_in_progress`, sprite_bits.row_sources; docs/vic.md rules).

The rule [VICE-src viciisc/vicii-draw-cycle.c: draw_sprites8 takes $D01D at pixel 6 and, on the
6569/6567 (colour latency), $D01C at pixel 7 of each cycle; draw_sprites shifts the row's register
one bit per pixel while the expansion flip-flop is set, and a multicolour pixel takes two bits every
other time (the pair flip-flop, cleared by a $D01C change)]: the row goes on from where its shift
register stands, it is not placed again.

The probes: sprite 1, one opaque pixel (its column 0) on every row, at X = probe; $D01E is cleared in
cycle 1 of line 110 and read in cycle 62, so only that line's pixels count. PAL: the sequencer draws
X 100 at slot 204 (cycle 26 pixel 4: cycle 1 starts at X $190 = 400, X wraps after $1F7).
Expected X worked by hand from the rule, in the comments.
"""

from __future__ import annotations

from vic_scenes import FULL, scene, sprite

from retro.chips.vic.constants import PAL
from retro.chips.vic.device import VicDevice
from retro.chips.vic.sprite_bits import row_sources

D01D, D01C, D01E = 0xD01D, 0xD01C, 0xD01E
PROBE = ["#" + "." * 23] * 21
HALVES = ["##.." * 6] * 21        # bits 1100 1100 ...


def at(line: int, cycle: int) -> int:
    return line * PAL.cycles_per_line + cycle - 1


def meets(x0: int, rows: list[str], probe: int, write: tuple[int, int, int] | None = None, line: int = 110,
          **flags) -> bool:
    """Whether sprite 0 at (x0, 100) meets the probe at X `probe` on `line`; `write`:
    (register, value, cycle of `line`)."""
    vic = VicDevice(scene(sprite(0, x0, 100, rows, **flags), sprite(1, probe, 100, PROBE),
                          registers={"$d011": 0x0B}).state)
    vic.read(D01E, at(line, 1))
    if write is not None:
        register, value, cycle = write
        vic.write(register, value, at(line, cycle))
    return vic.read(D01E, at(line, 62)) == 0x03


def test_row_sources_without_a_switch_are_the_plain_row():
    assert row_sources(False, False) == tuple(range(24))
    assert row_sources(True, False) == tuple(i // 2 for i in range(48))
    assert len(row_sources(False, True)) == 24 and len(row_sources(True, True)) == 48


def test_expansion_switched_on_mid_row_doubles_only_the_rest():
    # row from slot 204; the write in cycle 27 is taken at slot 208 + 6 = 214: pixel 10. Pixels 0-9
    # (X 100-109) one bit each, then bits 10-23 two pixels each: 28 more, the last at X 137. Placed
    # again as an expanded sprite the row would reach X 147; unexpanded X 123.
    write = (D01D, 0x01, 27)
    assert meets(100, FULL, 137, write)
    assert not meets(100, FULL, 138, write)
    assert not meets(100, FULL, 140, write)
    assert not meets(100, FULL, 124)                  # without the write


def test_expansion_switched_off_mid_row_shortens_only_the_rest():
    # expanded from slot 204, switched off at pixel 10: bits 0-4 drawn twice (pixels 0-9), then bits
    # 5-23 one pixel each from pixel 10: 19 pixels, the last at X 128 (placed again unexpanded: 123;
    # left expanded: 147)
    write = (D01D, 0x00, 27)
    assert meets(100, FULL, 128, write, expand_x=True)
    assert not meets(100, FULL, 129, write, expand_x=True)


def test_multicolour_switched_on_mid_row_takes_pairs_from_where_the_register_stands():
    # X 101 (from slot 205); the write in cycle 27 is taken at slot 208 + 7 = 215: pixel 10, which
    # clears the pair flip-flop: pixel 10 keeps bit 9 (1), then pairs from bit 11: (11,12) = 01,
    # (13,14) = 10, ... all opaque, each two pixels, to pixel 22 (pair 21,22 = 10); pair (23, -) = 00.
    # Hires the row is opaque only at bits 4k, 4k+1; multicolour from the row's start (pairs from
    # bit 0: 11, 00, ...) it would be too.
    write = (D01C, 0x01, 27)
    for probe in (111, 115, 116, 119, 120, 123):      # pixels 10, 14, 15, 18, 19, 22
        assert meets(101, HALVES, probe, write), probe
        assert not meets(101, HALVES, probe), probe
    assert not meets(101, HALVES, 124, write)         # pixel 23: the pair past the row


def test_the_next_line_shows_the_new_setting_from_its_start():
    # line 111's row is loaded after the write: expanded as a whole, X 100-147
    vic = VicDevice(scene(sprite(0, 100, 100, FULL), sprite(1, 147, 100, PROBE), registers={"$d011": 0x0B}).state)
    vic.write(D01D, 0x01, at(110, 27))
    vic.read(D01E, at(111, 1))
    assert vic.read(D01E, at(111, 62)) == 0x03


def test_a_write_before_the_row_starts_gives_the_whole_row_the_new_setting():
    # written in cycle 20 of line 110, before slot 204: the row is expanded from its start
    assert meets(100, FULL, 147, (D01D, 0x01, 20))
    assert not meets(100, FULL, 148, (D01D, 0x01, 20))


def test_a_write_after_the_row_ended_changes_nothing_until_the_next_load():
    # written in cycle 30 (the row ended at X 123, slot 227, cycle 29): line 110 shows the unexpanded
    # row only, not the rest of an expanded one (X 134-147 would fall in cycles 30-32)
    for probe in (134, 140, 147):
        assert not meets(100, FULL, probe, (D01D, 0x01, 30)), probe
    assert meets(100, FULL, 123, (D01D, 0x01, 30))
