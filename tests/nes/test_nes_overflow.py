"""Sprite overflow ($2002 bit 5): the evaluation worked by hand (retro/chips/ppu/overflow.py's rules:
nesdev wiki "PPU sprite evaluation", blargg's sprite_overflow_tests readme), the device's flag, and
`retro nes`'s report."""

from __future__ import annotations

import json
import subprocess
import sys

from nes_build import make_state

from retro.chips.ppu.overflow import overflow_dot_on_line, sprite_overflow
from retro.machines.nes import build_nes, ppu_of

HIDDEN = (0xF0, 0xF0, 0xF0, 0xF0)  # Y = 240: on no visible line, and no other byte in range either


def oam(*entries) -> bytes:
    data = bytearray(bytes(HIDDEN) * 64)
    for number, entry in enumerate(entries):
        data[number * 4:number * 4 + 4] = bytes(entry)
    return bytes(data)


def test_nine_sprites_on_a_line_set_the_flag_when_the_ninth_y_is_read():
    # 8 copies of 8 dots each from dot 65, so the 9th Y is read at dot 65 + 64 = 129
    nine = oam(*[(100, 0, 0, 8 * i) for i in range(9)])
    assert overflow_dot_on_line(nine, 100, 8) == 129
    assert overflow_dot_on_line(nine, 107, 8) == 129    # the last line the 8-line sprites cover
    assert overflow_dot_on_line(nine, 108, 8) is None
    assert overflow_dot_on_line(nine, 99, 8) is None


def test_out_of_range_sprites_before_cost_two_dots_each():
    entries = [(10, 0, 0, 0)] * 3 + [(100, 0, 0, 0)] * 9      # three sprites elsewhere first
    assert overflow_dot_on_line(oam(*entries), 100, 8) == 65 + 3 * 2 + 64


def test_eight_sprites_are_no_overflow():
    assert overflow_dot_on_line(oam(*[(100, 0, 0, 0)] * 8), 100, 8) is None


def test_the_diagonal_reads_the_tile_byte_of_the_sprite_after_a_miss():
    # 8 on line 100, sprite 8 elsewhere: the PPU then reads sprite 9's byte 1 (its tile) as the Y
    eight = [(100, 0, 0, 0)] * 8
    false_one = oam(*eight, (10, 0, 0, 0), (10, 100, 0, 0))       # tile 100 "is" on line 100
    assert overflow_dot_on_line(false_one, 100, 8) == 65 + 64 + 2 * 1
    missed = oam(*eight, (10, 0, 0, 0), (100, 0, 0, 0))           # a real 10th sprite, but its tile byte 0 is read
    assert overflow_dot_on_line(missed, 100, 8) is None


def test_double_height_sprites_cover_sixteen_lines():
    nine = oam(*[(100, 0, 0, 0)] * 9)
    assert overflow_dot_on_line(nine, 110, 8) is None
    assert overflow_dot_on_line(nine, 110, 16) == 129


def test_the_model_reports_line_dot_and_why_not():
    state = make_state(sprite=(100, 0, 0, 0), others=[(100, 0, 0, 8 * i) for i in range(1, 9)], mask=0x18)
    result = sprite_overflow(state)
    assert (result.set, result.line, result.dot, result.sprites_on_line) == (True, 100, 129, 9)
    assert result.dots_after_vblank == (262 - 241 + 100) * 341 + 129 - 1
    off = sprite_overflow(make_state(sprite=(100, 0, 0, 0), others=[(100, 0, 0, 0)] * 8, mask=0x00))
    assert not off.set and "rendering is off" in off.reason


def test_the_device_sets_bit_5_at_that_dot_keeps_it_through_reads_and_clears_it_at_pre_render():
    state = make_state(sprite=(100, 0, 0, 0), others=[(100, 0, 0, 0)] * 8, mask=0x10)
    ppu = ppu_of(build_nes(state))
    at = 100 * 341 + 129                                   # = 3 x 11410 + 19 ... read in the cycles around it
    before, after = (at - 1) // 3, -(-at // 3)
    assert ppu.read(0x2002, before) & 0x20 == 0
    assert ppu.read(0x2002, after) & 0x20 == 0x20
    assert ppu.read(0x2002, after + 1) & 0x20 == 0x20      # reading does not clear it
    ppu.advance(261 * 341 + 1)
    assert ppu.peek(0x2002) & 0x20 == 0                    # cleared with vblank at the pre-render line


def test_retro_nes_reports_the_overflow_beside_the_hit(tmp_path):
    scene = tmp_path / "crowd.toml"
    rows = "\n".join(f"[[oam]]\ny = 100\ntile = 0\nx = {8 * i}" for i in range(9))
    scene.write_text(f'chip = "nes"\n[ppu]\nmask = 0x18\n{rows}\n')
    out = subprocess.run([sys.executable, "-m", "retro", "nes", str(scene), "--json"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    assert report["sprite_overflow"] == {"set": True, "line": 100, "dot": 129,
                                         "dots_after_vblank": (262 - 241 + 100) * 341 + 128, "sprites_on_line": 9}
    text = subprocess.run([sys.executable, "-m", "retro", "nes", str(scene)], capture_output=True, text=True).stdout
    assert "sprite overflow: $2002 bit 5 set at line 100 dot 129" in text
