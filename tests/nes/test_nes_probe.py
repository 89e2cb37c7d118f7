"""Probe cartridges: the iNES header, the patched scene, and the delay routine's exact cycle count
(measured on the project's cycle-exact 6502 core, not computed from the formula under test)."""

from __future__ import annotations

import random

import pytest
from nes_build import make_state

from retro.analysis.nes_probe import MIN_DELAY, probe_image, probe_program
from retro.chips.ines import HEADER_SIZE, PRG_BANK_SIZE, nrom_image, parse_header
from retro.cpu.machine import Machine
from retro.errors import InputError


def test_nrom_header_fields():
    image = nrom_image(bytes(PRG_BANK_SIZE), bytes(8192), "vertical")
    # nesdev "INES": "NES" $1A, 1 x 16 KiB PRG, 1 x 8 KiB CHR, flags 6 bit 0 = vertical, mapper 0.
    assert image[:8] == b"NES\x1a\x01\x01\x01\x00" and image[8:16] == bytes(8)
    assert len(image) == 16 + 16384 + 8192
    assert parse_header(image).mirroring == "vertical"
    assert parse_header(nrom_image(bytes(2 * PRG_BANK_SIZE), bytes(8192), "horizontal")).prg_size == 32768
    with pytest.raises(InputError):
        nrom_image(bytes(100), bytes(8192), "vertical")
    with pytest.raises(InputError):
        nrom_image(bytes(PRG_BANK_SIZE), bytes(8192), "single")


def test_probe_image_carries_scene_chr_oam_and_vectors():
    state = make_state(mirroring="horizontal", sprite=(10, 20, 30, 40))
    image = probe_image(state, 1000)
    program = probe_program()
    prg = image[HEADER_SIZE:HEADER_SIZE + PRG_BANK_SIZE]
    assert image[HEADER_SIZE + PRG_BANK_SIZE:] == state.chr
    oam_at = program.symbols["scene_oam"] - program.origin
    assert prg[oam_at:oam_at + 4] == bytes([10, 20, 30, 40])
    reset = int.from_bytes(prg[0x3FFC:0x3FFE], "little")
    assert reset == program.symbols["reset"]
    nt1 = program.symbols["nametable1_high"] - program.origin
    assert prg[nt1] == 0x28                 # horizontal mirroring: CIRAM page 1 is $2800


@pytest.mark.parametrize("delay", [MIN_DELAY, MIN_DELAY + 1, MIN_DELAY + 4, 1300, 1303, 1304, 2583, 2584,
                                   *random.Random(9).sample(range(MIN_DELAY, 31_000), 12)])
def test_delay_routine_takes_exactly_the_requested_cycles(delay):
    image = probe_image(make_state(), delay)
    machine = Machine("2a03")
    program = probe_program()
    machine.bus.load(program.origin, image[HEADER_SIZE:HEADER_SIZE + PRG_BANK_SIZE])
    assert machine.call(program.symbols["delay"]).cycles == delay


def test_delay_below_minimum_is_refused():
    with pytest.raises(InputError):
        probe_image(make_state(), MIN_DELAY - 1)
