"""The field toolkit (retro/fields.py): one error format, "{source}: {field}: {message}", and the same
rules for every kind of file. Every expected message is written out by hand; the last tests make the
same mistake in a VIC-II scene, an NES scene and a routine spec and compare the messages' shapes."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from test_layers import package_imports

from retro.chips.vic.constants import VIDEOS
from retro.errors import InputError
from retro.fields import Fields
from retro.paths import ASM_DIR
from retro.routines.spec import parse_spec, read_spec_document
from retro.scenes import nes, vic

F = Fields("s.toml")


def message(call, *args, **kw) -> str:
    with pytest.raises(InputError) as caught:
        call(*args, **kw)
    return str(caught.value)


def test_the_toolkit_stands_on_errors_numbers_and_fileio_only():
    assert package_imports()["fields"] <= {"errors", "numbers", "fileio"}


# ---- unknown keys ------------------------------------------------------------------------------------

def test_an_unknown_key_is_named_with_its_table_and_the_known_keys_listed_in_order():
    assert message(F.table, {"ctrl": 0, "scrol_x": 1}, "ppu", {"scroll_x", "ctrl", "mask"}) == \
        "s.toml: ppu.scrol_x: unknown key (known: ctrl, mask, scroll_x)"
    assert message(F.table, {"chip": "nes", "colour": 1}, "", {"video", "chip"}) == \
        "s.toml: colour: unknown key (known: chip, video)"
    assert F.table({"ctrl": 0}, "ppu", {"ctrl"}) == {"ctrl": 0}
    assert F.table({"anything": 0}, "memory") == {"anything": 0}  # no `known`: names are the user's


def test_a_table_that_is_not_one():
    assert message(F.table, [1, 2], "ppu") == "s.toml: ppu: expected a table, got an array"
    assert message(F.table, "x", "ppu") == "s.toml: ppu: expected a table, got 'x'"
    assert message(F.array_of_tables, {"y": 1}, "oam") == \
        "s.toml: oam: expected an array of tables ([[oam]]), got a table"
    assert message(F.array_of_tables, [{"y": 1}, 7], "oam") == "s.toml: oam[1]: expected a table, got 7"
    assert message(F.array_of_tables, [{"z": 1}], "oam", {"y"}) == "s.toml: oam[0].z: unknown key (known: y)"


# ---- integers ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("value, shown", [(1.5, "1.5"), (2.0, "2.0"), (True, "true"), (False, "false"),
                                          ([1], "an array"), ({"a": 1}, "a table")])
def test_an_integer_is_never_a_float_a_boolean_an_array_or_a_table(value, shown):
    assert message(F.integer, value, "ppu.ctrl", 0, 255) == f"s.toml: ppu.ctrl: expected an integer, got {shown}"


@pytest.mark.parametrize("text", [255, "255", "$ff", "$FF", "0xff", "%11111111", "0b11111111", " 255 ", "2_55"])
def test_an_integer_may_be_written_in_any_notation(text):
    assert F.integer(text, "x", 0, 255) == 255


def test_strings_false_takes_toml_integers_only():
    assert F.integer(7, "hitbox.inset", strings=False) == 7
    assert message(F.integer, "7", "hitbox.inset", strings=False) == \
        "s.toml: hitbox.inset: expected an integer, got '7'"


def test_ranges_are_inclusive_and_printed_lo_dot_dot_hi():
    assert F.integer(0, "x", 0, 255) == 0 and F.integer(255, "x", 0, 255) == 255
    assert message(F.integer, 256, "ppu.mask", 0, 255) == "s.toml: ppu.mask: 256 is out of range 0..255"
    assert message(F.integer, -1, "oam[0].x", 0, 255) == "s.toml: oam[0].x: -1 is out of range 0..255"
    assert message(F.integer, "$100", "x", 0, 255) == "s.toml: x: '$100' is out of range 0..255"
    assert message(F.byte, 300, "color") == "s.toml: color: 300 is out of range 0..255"


def test_text_that_is_no_number():
    assert message(F.integer, "ten", "x") == "s.toml: x: not a number: 'ten' (use $C000, 0xc000, %1010 or 49152)"
    assert message(Fields("s.toml", number_characters=4).integer, "12345", "x") == \
        "s.toml: x: not a number: '12345'... (5 characters)"


def test_integers_one_for_all_or_a_list_of_count():
    assert F.integers(2, "inset", 4, -24, 24) == (2, 2, 2, 2)
    assert F.integers([1, 2, 3, 4], "inset", 4, -24, 24) == (1, 2, 3, 4)
    assert message(F.integers, [1, 2], "inset", 4, -24, 24) == \
        "s.toml: inset: expected an integer or a list of 4, got 2 items"
    assert message(F.integers, [1, 2, 30, 4], "inset", 4, -24, 24) == "s.toml: inset[2]: 30 is out of range -24..24"


def test_byte_lists():
    assert F.byte_list([0, "$ff"], "glyph", 2) == [0, 255]
    assert message(F.byte_list, [1, 2], "memory.charset.1", 8) == \
        "s.toml: memory.charset.1: expected a list of 8 bytes, got 2"
    assert message(F.byte_list, "ff", "glyph", 8) == "s.toml: glyph: expected a list of 8 bytes, got 'ff'"
    assert message(F.byte_list, [1, 256], "glyph", 2) == "s.toml: glyph[1]: 256 is out of range 0..255"
    assert message(F.byte_list, [1, 2, 3], "bytes", most=2) == "s.toml: bytes: more than 2 bytes"


# ---- required keys, flags, strings, choices ----------------------------------------------------------

def test_a_missing_key_is_named_with_its_table():
    assert F.required({"y": 5}, "y", "oam[0]") == 5
    assert message(F.required, {}, "y", "oam[0]") == "s.toml: oam[0].y: missing"
    assert message(F.required, {}, "program", "", "the [program] table") == \
        "s.toml: program: missing: the [program] table"


def test_exactly_one_of():
    assert F.exactly_one({"rows": 1, "x": 2}, ("data", "rows", "file"), "sprite[0]") == "rows"
    assert message(F.exactly_one, {}, ("data", "rows", "file"), "sprite[0]") == \
        "s.toml: sprite[0]: give exactly one of data, rows, file (got none)"
    assert message(F.exactly_one, {"data": 1, "file": 2}, ("data", "rows", "file"), "sprite[0]") == \
        "s.toml: sprite[0]: give exactly one of data, rows, file (got data, file)"


def test_flags_are_booleans_only():
    assert F.flag(True, "enabled") is True
    assert message(F.flag, 1, "sprite[0].enabled") == "s.toml: sprite[0].enabled: expected true or false, got 1"
    assert message(F.flag, "yes", "touching") == "s.toml: touching: expected true or false, got 'yes'"


def test_strings():
    assert F.string(" a ", "name") == " a "
    assert message(F.string, "  ", "name") == "s.toml: name: expected a non-empty string, got '  '"
    assert message(F.string, 3, "name") == "s.toml: name: expected a non-empty string, got 3"
    assert message(F.string, "abc", "name", most=2) == "s.toml: name: longer than 2 characters"


def test_choices():
    assert F.choice("pal", "video", ("ntsc", "pal")) == "pal"
    assert message(F.choice, "secam", "video", ("ntsc", "pal")) == \
        "s.toml: video: expected one of 'ntsc', 'pal', got 'secam'"
    assert message(F.choice, 3, "video", {"ntsc": object()}) == "s.toml: video: expected one of 'ntsc', got 3"
    assert message(F.choice, "x", "video", ("pal",), labels={"pal": "'pal' (6569)"}) == \
        "s.toml: video: expected one of 'pal' (6569), got 'x'"
    assert F.choice("$0314", "irq", ("$fffe", "$0314"), fold_case=True) == "$0314"
    assert F.choice("CPU", "cpu", ("cpu",), fold_case=True) == "cpu"
    assert message(F.choice, "CPU", "cpu", ("cpu",)) == "s.toml: cpu: expected one of 'cpu', got 'CPU'"


# ---- files -------------------------------------------------------------------------------------------

def test_files_are_relative_to_the_document(tmp_path, monkeypatch):
    folder = tmp_path / "scenes"
    folder.mkdir()
    (folder / "a.bin").write_bytes(b"\x01\x02")
    (folder / "sub").mkdir()
    monkeypatch.chdir(tmp_path)  # not the scene's folder: the name must resolve against the scene's
    fields = Fields("scenes/s.toml")
    assert fields.file("a.bin", "chr.file") == Path("scenes/a.bin")
    assert fields.file("a.bin", "chr.file", resolve=True) == folder / "a.bin"
    assert fields.file(str(folder / "a.bin"), "chr.file") == folder / "a.bin"
    assert fields.read_file("a.bin", "chr.file") == b"\x01\x02"
    assert message(fields.file, "nope.bin", "chr.file", "CHR file") == \
        "scenes/s.toml: chr.file: CHR file 'nope.bin' not found (looked for scenes/nope.bin)"
    assert message(fields.file, "sub", "chr.file") == \
        "scenes/s.toml: chr.file: file 'sub' is a folder, not a file (scenes/sub)"
    assert message(fields.file, 3, "chr.file") == "scenes/s.toml: chr.file: expected a file name, got 3"
    assert message(fields.file, "a\0b", "chr.file") == "scenes/s.toml: chr.file: a file name cannot hold a NUL character"
    assert Fields("spec.toml", folder=folder).file("a.bin", "program.file") == folder / "a.bin"


def test_an_error_without_a_field_names_the_file_only():
    assert str(F.error("", "no cases")) == "s.toml: no cases"


# ---- the same mistake in every kind of file reads the same way ---------------------------------------

SHAPE = re.compile(r"^(?P<source>[^:]+): (?P<field>[^:]+): (?P<message>.*)$")


def vic_error(sprite: dict) -> str:
    doc = {"chip": "vic-ii", "sprite": [{"index": 0, "data": "00" * 63, **sprite}]}
    return message(vic.parse, doc, "v.toml")


def nes_error(entry: dict) -> str:
    return message(nes.parse, {"chip": "nes", "oam": [{"y": 0, "tile": 0, "x": 0, **entry}]}, "n.toml")


def spec_error(cycles: dict) -> str:
    path = ASM_DIR / "mul8.toml"
    doc = read_spec_document(path)
    doc["cycles"] = {**doc.get("cycles", {}), **cycles}
    return message(parse_spec, doc, path, "r.toml")


def shapes(*messages: str) -> list[tuple[str, str, str]]:
    found = [SHAPE.match(m) for m in messages]
    assert all(found), messages
    return [(m["source"], m["field"], m["message"]) for m in found]


def test_an_unknown_key_reads_the_same_in_scenes_and_specs():
    (vs, vf, vm), (ns, nf, nm), (rs, rf, rm) = shapes(vic_error({"flip": 1}), nes_error({"flip": 1}),
                                                      spec_error({"maxx": 1}))
    assert (vs, vf, ns, nf, rs, rf) == ("v.toml", "sprite[0].flip", "n.toml", "oam[0].flip", "r.toml", "cycles.maxx")
    assert vm.startswith("unknown key (known: behind, color, data,")
    assert nm == "unknown key (known: attr, tile, x, y)"
    assert rm == "unknown key (known: limit, loops, max, static)"


def test_a_float_where_an_integer_goes_reads_the_same_in_scenes_and_specs():
    assert shapes(vic_error({"x": 1.5}), nes_error({"x": 1.5}), spec_error({"max": 1.5})) == [
        ("v.toml", "sprite[0].x", "expected an integer, got 1.5"),
        ("n.toml", "oam[0].x", "expected an integer, got 1.5"),
        ("r.toml", "cycles.max", "expected an integer, got 1.5")]
    assert shapes(vic_error({"y": True}), nes_error({"y": True}), spec_error({"max": True})) == [
        ("v.toml", "sprite[0].y", "expected an integer, got true"),
        ("n.toml", "oam[0].y", "expected an integer, got true"),
        ("r.toml", "cycles.max", "expected an integer, got true")]


def test_out_of_range_reads_the_same_in_scenes_and_specs():
    assert shapes(vic_error({"x": 512}), nes_error({"x": 256}), spec_error({"max": 0})) == [
        ("v.toml", "sprite[0].x", "512 is out of range 0..511"),
        ("n.toml", "oam[0].x", "256 is out of range 0..255"),
        ("r.toml", "cycles.max", f"0 is out of range 1..{1 << 40}")]


def test_the_vic_scene_offers_every_video_standard_the_chip_constants_name():
    text = message(vic.parse, {"chip": "vic-ii", "video": "secam"}, "v.toml")
    listed = ", ".join(f"'{name}' ({standard.chip})" for name, standard in VIDEOS.items())
    assert text == f"v.toml: video: expected one of {listed}, got 'secam'"
    for name, standard in VIDEOS.items():
        assert vic.parse({"chip": "vic-ii", "video": name}, "v.toml").state.video is standard
