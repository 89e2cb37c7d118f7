"""The VIC-II reading memory (retro/chips/vic/fetch.py): sprite data through the pointers, the screen
and character set through $D018 and CIA 2's bank bits, colour RAM at $D800, the character ROM's
window; a scene's memory placed where the chip fetches it back."""

from __future__ import annotations

import numpy as np
import pytest

from retro.chips.vic.constants import PAL, REGISTER_COUNT, SPRITE_BYTES, SPRITE_COUNT
from retro.chips.vic.fetch import VicBankPort, VicFetcher, memory_parts, sprite_line_counts, sprites_drawn_between, \
    vic_bases
from retro.chips.vic.graphics import VicMemory
from retro.chips.vic.model import VicState, run_frames
from retro.errors import InputError, RunError
from retro.loaders.basic_stub import sys_line
from retro.machines.c64 import build_c64, vic_of
from retro.program import Program
from vic_scenes import FULL, scene, sprite

FRAME = PAL.frame_cycles
BLANK_STATE = VicState(PAL, bytes(REGISTER_COUNT), (bytes(SPRITE_BYTES),) * SPRITE_COUNT)


def machine_with(registers: dict[int, int], char_rom: bytes | None = None):
    """A C64 whose VIC-II reads memory, registers set through the device as a program would."""
    machine = build_c64(BLANK_STATE, reads_memory=True, char_rom=char_rom)
    vic = vic_of(machine)
    for address, value in registers.items():
        vic.write(address, value, machine.cycle)
    return machine, vic


def two_sprites(extra: dict[int, int] | None = None) -> dict[int, int]:
    """Sprites 0 and 1 enabled at the same place (Y 100, X 100), text mode, display on."""
    return {0xD000: 100, 0xD001: 100, 0xD002: 100, 0xD003: 100, 0xD011: 0x1B, 0xD015: 0x03, **(extra or {})}


def latch_after_a_frame(machine, vic, register: int = 0xD01E) -> int:
    machine.mpu.processorCycles += 2 * FRAME
    return vic.read(register, machine.cycle)


@pytest.mark.parametrize("d018, bank, bases", [(0x14, 0, (0x0400, 0x1000, 0x0000)),
                                               (0x1E, 0, (0x0400, 0x3800, 0x2000)),
                                               (0x38, 3, (0xCC00, 0xE000, 0xE000)),
                                               (0xF2, 1, (0x7C00, 0x4800, 0x4000))])
def test_d018_and_the_bank_place_screen_charset_and_bitmap(d018, bank, bases):
    registers = bytearray(REGISTER_COUNT)
    registers[0x18] = d018
    assert vic_bases(bytes(registers), bank) == bases


def test_the_bank_is_port_a_inverted_and_an_input_pin_reads_1():
    port = VicBankPort()
    assert port.bank == 0  # the KERNAL's $97 / $3F
    port.write(0xDD00, 0x94, 0)
    assert port.bank == 3
    port.write(0xDD02, 0x00, 0)  # all inputs: the pull-ups read %11
    assert port.bank == 0 and port.read(0xDD00, 0) & 3 == 3
    port.set_bank(2)
    assert port.bank == 2 and port.read(0xDD00, 0) & 3 == 1
    with pytest.raises(RunError, match=r"CIA 2 at \$DD04"):
        port.read(0xDD04, 0)


def test_sprite_data_is_fetched_through_the_pointers():
    machine, vic = machine_with(two_sprites())
    ram = machine.bus.memory
    ram[0x0340:0x0340 + SPRITE_BYTES] = [0xFF] * SPRITE_BYTES  # block 13
    ram[0x07F8] = ram[0x07F9] = 13  # $D018 = 0 after power-on: the screen at $0000, pointers at $03F8
    assert latch_after_a_frame(machine, vic) == 0  # the pointers at $03F8 still name block 0 (zeros)
    ram[0x03F8] = ram[0x03F9] = 13
    assert latch_after_a_frame(machine, vic) == 0x03
    ram[0x03F9] = 14  # sprite 1 now shows an empty block
    assert latch_after_a_frame(machine, vic) == 0


def test_the_pointers_follow_d018_and_the_data_follows_the_bank():
    machine, vic = machine_with(two_sprites({0xD018: 0x14}))
    ram = machine.bus.memory
    ram[0x07F8] = ram[0x07F9] = 13
    ram[0xC340:0xC340 + SPRITE_BYTES] = [0xFF] * SPRITE_BYTES
    assert latch_after_a_frame(machine, vic) == 0  # bank 0: block 13 at $0340 is empty
    machine.bus.page_devices[0xDD].write(0xDD00, 0x94, machine.cycle)  # bank 3: $C000
    ram[0xC7F8] = ram[0xC7F9] = 13
    assert latch_after_a_frame(machine, vic) == 0x03


def _text_over_sprite(colour: int, char_rom: bool):
    """Sprite 0 over the whole screen of character 1 (pattern %01010101), multicolor text mode;
    the character set at $2000 ($D018 = $18) or in the character ROM ($D018 = $14)."""
    d018 = 0x14 if char_rom else 0x18
    rom = bytes(0x1000)
    if char_rom:
        rom = bytes(8) + bytes([0x55] * 8) + bytes(0x1000 - 16)
    machine, vic = machine_with({0xD000: 100, 0xD001: 100, 0xD011: 0x1B, 0xD016: 0xD8, 0xD018: d018, 0xD015: 1},
                                char_rom=rom if char_rom else None)
    ram = machine.bus.memory
    ram[0x0400:0x0400 + 1000] = [1] * 1000
    ram[0xD800:0xD800 + 1000] = [colour] * 1000
    ram[0x07F8] = 13
    ram[0x0340:0x0340 + SPRITE_BYTES] = [0xFF] * SPRITE_BYTES
    if not char_rom:
        ram[0x2008:0x2010] = [0x55] * 8
    return machine, vic


@pytest.mark.parametrize("colour, collides", [(1, True), (9, False)])
def test_colour_ram_decides_multicolor_characters(colour, collides):
    # hires (colour RAM bit 3 clear): every other pixel is foreground; multicolor: the pairs are %01,
    # background colour 1, which never collides
    machine, vic = _text_over_sprite(colour, char_rom=False)
    assert latch_after_a_frame(machine, vic, 0xD01F) == (1 if collides else 0)


def test_the_character_rom_window_is_read_from_the_image_given():
    machine, vic = _text_over_sprite(1, char_rom=True)
    assert latch_after_a_frame(machine, vic, 0xD01F) == 1


def test_without_the_character_rom_a_latch_that_needs_it_is_refused():
    machine = build_c64(BLANK_STATE, reads_memory=True)
    vic = vic_of(machine)
    for address, value in two_sprites({0xD018: 0x14}).items():
        vic.write(address, value, machine.cycle)
    machine.mpu.processorCycles += FRAME
    assert vic.read(0xD01E, machine.cycle) == 0  # sprite data in RAM: known
    with pytest.raises(RunError, match=r"\$D01F.*character ROM.*RETRO_C64_CHARGEN"):
        vic.read(0xD01F, machine.cycle)
    machine.bus.memory[0x07F8] = 0x40 + 2  # sprite 0's data at $1080: inside the ROM's window
    with pytest.raises(RunError, match=r"\$D01E.*sprite data.*character ROM"):
        vic.read(0xD01E, machine.cycle + FRAME)


def test_a_scene_placed_in_memory_is_fetched_back_and_collides_the_same():
    ring = ["#" * 24] + ["#" + "." * 22 + "#"] * 19 + ["#" * 24]
    placed = scene(sprite(0, 100, 100), sprite(1, 110, 105, rows=ring, multicolor=False),
                   registers={"$d018": 0x1E, "$d016": 0xD8},
                   memory={"screen": {"fill": 3}, "color": {"fill": 9}, "charset": {"3": [0xF0] * 8}})
    fetcher = VicFetcher([0] * 0x10000, VicBankPort())
    for _, at, values in memory_parts(placed.state, 0):
        fetcher.ram[at:at + len(values)] = values
    fetched = fetcher.state_for(placed.state, placed.state.registers)
    assert fetched.sprite_data == placed.state.sprite_data
    for part in ("screen", "color", "charset"):
        assert np.array_equal(getattr(fetched.memory, part), getattr(placed.state.memory, part)), part
    before, after = run_frames(placed.state), run_frames(fetched)
    assert (after.d01e, after.d01f, after.first_d01e) == (before.d01e, before.d01f, before.first_d01e)
    assert before.d01e == 0x03 and before.d01f != 0  # the comparison is not between two empty frames


def test_a_scene_whose_parts_overlap_is_refused_naming_d018():
    overlapping = scene(sprite(0, 100, 100), memory={"screen": {"fill": 3}, "charset": {"3": [0xF0] * 8}},
                        registers={"$d018": 0x22})  # screen at $0800, charset at $0800-$0FFF
    with pytest.raises(InputError, match=r"\$D018 = \$22.*overlaps the screen at \$0800"):
        memory_parts(overlapping.state, 0)
    on_zero_page = scene(sprite(0, 100, 100), memory={"charset": {"3": [0xF0] * 8}}, registers={"$d018": 0x10})
    with pytest.raises(InputError, match="zero page"):
        memory_parts(on_zero_page.state, 0)


def test_memory_is_read_only_where_a_sprite_can_draw():
    registers = bytearray(REGISTER_COUNT)
    registers[0x15], registers[0x01] = 1, 100  # sprite 0 on lines 101-121
    counts = sprite_line_counts(PAL, bytes(registers))
    cycles = PAL.cycles_per_line
    assert not sprites_drawn_between(PAL, counts, 0, 90 * cycles)
    assert sprites_drawn_between(PAL, counts, 100 * cycles, 101 * cycles)
    assert sprites_drawn_between(PAL, counts, 90 * cycles, 130 * cycles)
    assert sprites_drawn_between(PAL, counts, FRAME + 110 * cycles, FRAME + 110 * cycles + 1)
    assert not sprites_drawn_between(PAL, counts, 200 * cycles, 300 * cycles)
    assert not sprites_drawn_between(PAL, counts, 300 * cycles, FRAME + 90 * cycles)
    assert sprites_drawn_between(PAL, counts, 300 * cycles, FRAME + 100 * cycles)  # across the frame's end
    registers[0x15] = 0
    assert sprite_line_counts(PAL, bytes(registers)) is None
    assert not sprites_drawn_between(PAL, None, 0, 3 * FRAME)


@pytest.mark.parametrize("text, address, refused", [(b"\x9e2069 /T.L.R/", 2069, False),
                                                    (b"\x9e2069\xad2", None, True),  # SYS 2069/2
                                                    (b"\x9e2069E2", None, True)])
def test_text_after_the_sys_number_ends_the_expression_unless_an_operator_follows(text, address, refused):
    line = bytes([0, 0]) + text + b"\0"
    link = 0x0801 + 2 + len(line)
    program = Program(code=bytes([link & 0xFF, link >> 8]) + line + b"\0\0", origin=0x0801, source="p.prg")
    if refused:
        with pytest.raises(InputError, match="plain number"):
            sys_line(program)
        return
    found = sys_line(program)
    assert found.address == address and any("/T.L.R/" in note for note in found.notes)


def test_a_run_with_a_scene_collides_through_memory(tmp_path):
    """`retro run --scene`: the scene's sprites are put in memory and collide there; a program
    that clears sprite 1's data makes them stop colliding."""
    from retro.commands import run

    scene_file = tmp_path / "two.toml"
    scene_file.write_text('chip = "vic-ii"\n[registers]\n"$d011" = 0x1b\n"$d018" = 0x14\n'
                          '[[sprite]]\nindex = 0\nx = 100\ny = 100\ndata = "' + "ff" * 63 + '"\n'
                          '[[sprite]]\nindex = 1\nx = 110\ny = 100\ndata = "' + "ff" * 63 + '"\n')
    stub = bytes([0x0B, 0x08, 0x0A, 0x00, 0x9E]) + b"2061" + bytes([0, 0, 0])
    prg = tmp_path / "p.prg"

    def collisions_seen(before: list[int]) -> int:
        """Run `before`, then OR every $D01E read into $C000 for two frames."""
        at = 0x080D + len(before)
        loop = [0xAD, 0x1E, 0xD0, 0x0D, 0x00, 0xC0, 0x8D, 0x00, 0xC0, 0x4C, at & 0xFF, at >> 8]
        prg.write_bytes(bytes([0x01, 0x08]) + stub + bytes(before + loop))
        report = run.run_c64_program(prg, frames=2, scene=scene_file, peeks=["$C000"])
        return report.peeks["$C000"][0], report.machine.bus.memory[0x07F9]

    seen, pointer = collisions_seen([])
    assert seen == 0x03
    block = pointer * 64
    clear = [0xA9, 0x00, 0xA2, 0x3F, 0x9D, block & 0xFF, block >> 8, 0xCA, 0x10, 0xFA]  # zero sprite 1's block
    assert collisions_seen(clear)[0] == 0x00


def test_a_scene_names_the_bank_its_memory_goes_to(tmp_path):
    from retro.analysis.c64_run import c64_for
    from retro.scenes.vic import load

    scene_file = tmp_path / "b.toml"
    scene_file.write_text('chip = "vic-ii"\n[registers]\n"$d018" = 0x14\n[memory]\nbank = 2\n'
                          'screen = { fill = 7 }\n')
    machine = c64_for(Program(code=b"\x60", origin=0xC000, source="p"), load(scene_file))
    assert machine.bus.memory[0x8400:0x8400 + 1000] == [7] * 1000 and machine.bus.memory[0x0400] == 0
    assert vic_of(machine).fetcher.bank_port.bank == 2
    scene_file.write_text('chip = "vic-ii"\n[memory]\nbank = 4\n')
    with pytest.raises(InputError, match="memory.bank"):
        load(scene_file)
