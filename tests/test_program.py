"""PRG files and VICE label files: the way ACME, 64tass and ca65 users bring their own binaries."""

from __future__ import annotations

import pytest

from retro.errors import InputError
from retro.loaders import load_program, parse_symbols, symbol_tables
from retro.program import Program, format_vice_labels, parse_prg, prg_bytes


def parse_vice_labels(text: str, source: str = "labels") -> dict[str, int]:
    symbols, ambiguous = symbol_tables(parse_symbols(text, source))
    assert not ambiguous
    return symbols


def load_prg_file(path, labels=None) -> Program:
    return load_program(path, symbols=labels)


def test_prg_round_trip_and_header_is_little_endian():
    program = Program(code=bytes([0xA9, 0x01, 0x60]), origin=0xC000, symbols={"f": 0xC000})
    data = prg_bytes(program)
    assert data == bytes([0x00, 0xC0, 0xA9, 0x01, 0x60])
    back = parse_prg(data)
    assert (back.origin, back.code) == (0xC000, program.code)


@pytest.mark.parametrize("size", [0, 1])
def test_prg_shorter_than_its_header(size, tmp_path):
    path = tmp_path / "short.prg"
    path.write_bytes(b"\x01" * size)
    with pytest.raises(InputError) as error:
        load_prg_file(path)
    assert str(error.value).startswith(f"{path}: ") and "2-byte load address" in str(error.value)


def test_prg_running_past_the_address_space():
    with pytest.raises(InputError, match="past \\$FFFF"):
        parse_prg(bytes([0xFE, 0xFF, 1, 2, 3]), source="big.prg")
    assert parse_prg(bytes([0xFE, 0xFF, 1, 2])).end == 0x10000


def test_vice_labels_round_trip():
    symbols = {"start": 0xC000, "loop": 0xC004, "table_lo": 0x0800, "zp": 0x00FB}
    text = format_vice_labels(symbols)
    assert text.splitlines()[0] == "al C:00fb .zp"
    assert parse_vice_labels(text) == symbols


def test_label_lines_as_acme_64tass_and_ld65_write_them():
    text = ("al C:c000 .acme_label\n"   # ACME --vicelabels
            "al c010 .tass_label\n"     # 64tass --vice-labels
            "al 00C020 .ca65_label\n"   # ld65 -Ln
            "\n# comment\n")
    assert parse_vice_labels(text) == {"acme_label": 0xC000, "tass_label": 0xC010, "ca65_label": 0xC020}


def test_malformed_label_file_names_file_and_line(tmp_path):
    labels = tmp_path / "bad.lbl"
    labels.write_text("al C:c000 .ok\n\nadd_label c000 start\n")
    prg = tmp_path / "x.prg"
    prg.write_bytes(bytes([0x00, 0xC0, 0x60]))
    with pytest.raises(InputError) as error:
        load_prg_file(prg, labels)
    assert str(error.value).startswith(f"{labels}:3: ")


def test_label_address_above_ffff_is_left_out_never_wrapped():
    # ld65 -Ln writes a constant wider than 16 bits (or a negative, FFFFFFF0) like any label
    assert parse_vice_labels("al C:c000 .ok\nal 010000 .far\nal FFFFFFF0 .neg\n", source="lbl") == {"ok": 0xC000}


def test_loading_a_prg_with_labels(tmp_path):
    prg = tmp_path / "r.prg"
    prg.write_bytes(bytes([0x00, 0x10, 0xE8, 0x60]))
    labels = tmp_path / "r.lbl"
    labels.write_text("al C:1000 .inc_x\n")
    program = load_prg_file(prg, labels)
    assert (program.origin, program.code, program.symbols) == (0x1000, bytes([0xE8, 0x60]), {"inc_x": 0x1000})
    assert program.address_of("inc_x") == 0x1000
    with pytest.raises(InputError, match="unknown label 'nope'"):
        program.address_of("nope")
    with pytest.raises(InputError, match="not found"):
        load_prg_file(prg, tmp_path / "missing.lbl")
