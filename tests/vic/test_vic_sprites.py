"""Sprite formats: raw .spr blocks, rows, PNG; the checked-in sample sprites."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from retro.errors import InputError
from retro.render.sprite_png import write_png
from retro.sprites import (
    decode,
    encode,
    opaque_mask,
    parse_hex,
    parse_rows,
    read_png,
    read_spr,
    write_spr,
)

SPRITES = Path(__file__).resolve().parents[2] / "sprites"
SAMPLES = ["ball", "ring", "ship", "bullet", "bar", "pentagon", "lshape", "full", "mc_ball", "mc_ship", "mc_gem"]


def test_bits_are_msb_first_three_bytes_per_row():
    data = bytes([0x80, 0x00, 0x01] + [0] * 60)
    bits = decode(data)
    assert bits[0, 0] == 1 and bits[0, 23] == 1 and bits.sum() == 2


def test_multicolor_pairs_and_opacity():
    data = bytes([0b00011011] + [0] * 62)  # pairs 00, 01, 10, 11
    assert decode(data, True)[0, :4].tolist() == [0, 1, 2, 3]
    assert opaque_mask(data, True)[0, :8].tolist() == [False, False, True, True, True, True, True, True]


def test_encode_decode_round_trip():
    rng = np.random.default_rng(1)
    data = bytes(rng.integers(0, 256, 63, dtype=np.uint8))
    assert encode(decode(data)) == data
    assert encode(decode(data, True), True) == data


def test_rows_and_hex():
    rows = ["#" + "." * 23] + ["." * 24] * 20
    assert parse_rows(rows, False)[0] == 0x80
    with pytest.raises(InputError, match="rows"):
        parse_rows(rows[:20], False)
    assert len(parse_hex("ff " * 64)) == 63
    with pytest.raises(InputError):
        parse_hex("ff " * 10)


def test_spr_frames(tmp_path):
    a, b = bytes([1] * 63), bytes([2] * 63)
    path = write_spr(tmp_path / "anim.spr", [a, b])
    assert path.stat().st_size == 128
    assert read_spr(path, 1) == b
    with pytest.raises(InputError, match="frame"):
        read_spr(path, 2)
    (tmp_path / "odd.spr").write_bytes(b"\0" * 70)
    with pytest.raises(InputError, match="64-byte"):
        read_spr(tmp_path / "odd.spr")


@pytest.mark.parametrize("multicolor", [False, True])
def test_png_round_trip(tmp_path, multicolor):
    data = read_spr(SPRITES / ("mc_ball.spr" if multicolor else "ship.spr"))
    write_png(tmp_path / "s.png", data, multicolor)
    assert read_png(tmp_path / "s.png", multicolor) == data


@pytest.mark.parametrize("name", SAMPLES)
def test_sample_sprites_are_64_byte_blocks_and_not_empty(name):
    raw = (SPRITES / f"{name}.spr").read_bytes()
    assert len(raw) == 64
    assert opaque_mask(raw[:63], name.startswith("mc_")).any()
    assert (SPRITES / "previews" / f"{name}.png").is_file()


def test_sample_shapes_match_their_definitions():
    ball = opaque_mask(read_spr(SPRITES / "ball.spr"))
    ys, xs = np.mgrid[0:21, 0:24]
    assert (ball == ((xs - 11.5) ** 2 + (ys - 10) ** 2 <= 100)).all()
    bar = opaque_mask(read_spr(SPRITES / "bar.spr"))
    assert bar.sum() == 21 and bar[:, 11].all()
