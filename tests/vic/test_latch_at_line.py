"""`--at-line L` starts from the state the frame drawn so far leaves: sprites overlapping on line 234,
a routine entered on line 240 reads the collision bit set since 234 (and $00 on a second read: the
read clears it), as a collision check in a raster interrupt would on the machine."""

from __future__ import annotations

import numpy as np
import pytest
from vic_scenes import scene, sprite

from retro.assembler import assemble_text
from retro.chips.vic.model import frame_collisions
from retro.machines.c64 import build_c64
from retro.routines.runner import RasterStart, RoutineRunner
from retro.testing import spec_from_dict

READ_TWICE = """
.org $c000
entry:  lda {reg}
        sta $02
        lda {reg}
        sta $03
        lda $d019
        sta $04
        rts
"""
OVERLAP_LINE = 234


def sprites_meeting_on_line_234():
    # sprite 0's rows are on lines 214-234, sprite 1's on 234-254, both solid at the same X
    return scene(sprite(0, 100, 213), sprite(1, 100, 233))


def sprite_over_text_on_line_234():
    # text row 22 is lines 227-234 (YSCROLL 3): solid characters in columns 8-12 of that row only;
    # sprite 0's rows are on lines 234-254
    memory = {"screen": {"fill": 32, "cells": [{"col": c, "row": 22, "value": 0xA0} for c in range(8, 13)]},
              "charset": {"160": [0xFF] * 8}}
    return scene(sprite(0, 100, 233), memory=memory)


CASES = [("$d01e", sprites_meeting_on_line_234, 0b11, 0x04), ("$d01f", sprite_over_text_on_line_234, 0b01, 0x02)]


@pytest.mark.parametrize("register, make, bits, irq_bit", CASES)
def test_the_scene_meets_only_on_line_234(register, make, bits, irq_bit):
    events = frame_collisions(make().state)
    lines = events.ss_pixels[0] if register == "$d01e" else events.sb_pixels[0]
    assert set(np.unique(lines).tolist()) == {OVERLAP_LINE}


@pytest.mark.parametrize("register, make, bits, irq_bit", CASES)
def test_entered_on_line_240_the_bit_is_set_since_234_and_a_second_read_clears_it(register, make, bits, irq_bit):
    program = assemble_text(READ_TWICE.format(reg=register))
    for line, expected, irq in ((240, bits, irq_bit), (230, 0, 0)):   # after the overlap / before it
        machine = build_c64(make().state, start_line=line)
        machine.load(program)
        machine.call("entry")
        first, second, d019 = machine.peek(2, 3)
        assert (first, second) == (expected, 0), (register, line)
        assert d019 & irq_bit == irq, (register, line)   # $D019 latched it too (not acknowledged)


@pytest.mark.parametrize("register, make, bits, irq_bit", CASES)
def test_a_checked_routine_at_line_240_reads_it_on_every_call(tmp_path, register, make, bits, irq_bit):
    source = tmp_path / "read.s"
    source.write_text(READ_TWICE.format(reg=register))
    (tmp_path / "refs.py").write_text(f"def latched(a):\n    return ({bits}, 0)\n")
    routine = spec_from_dict({"program": {"file": "read.s", "entry": "entry"}, "inputs": {"a": "A"},
                              "outputs": {"first": "$02", "second": "$03"},
                              "reference": {"function": "refs.py:latched"}}, base=tmp_path)
    runner = RoutineRunner(routine, 0, RasterStart(make(), 240, 1))
    for case in ((0,), (1,), (2,)):   # every call starts from the frame drawn up to line 240 again
        assert runner.run(case)[0] == (bits, 0)
