"""Small builders for hand-made PPU states in tests (independent of the scene parser)."""

from __future__ import annotations

from retro.chips.ppu.constants import CHR_SIZE, CIRAM_SIZE, NTSC, OAM_SIZE
from retro.chips.ppu.state import PpuState

SOLID = ["33333333"] * 8


def tile_bytes(rows: list[str]) -> bytes:
    """8 strings of 8 digits 0-3 -> 16 CHR bytes (plane 0 = bit 0 of each pixel, plane 1 = bit 1)."""
    low = [int("".join("1" if ch in "13" else "0" for ch in row), 2) for row in rows]
    high = [int("".join("1" if ch in "23" else "0" for ch in row), 2) for row in rows]
    return bytes(low + high)


def one_pixel(row: int, col: int, value: int = 3) -> list[str]:
    rows = ["00000000"] * 8
    rows[row] = "0" * col + str(value) + "0" * (7 - col)
    return rows


def make_state(*, tiles: dict[tuple[int, int], list[str]] | None = None, cells: dict[tuple[int, int, int], int] | None = None,
               sprite: tuple[int, int, int, int] = (119, 1, 0, 128), others: list[tuple[int, int, int, int]] = (),
               ctrl: int = 0, mask: int = 0x1E, scroll_x: int = 0, scroll_y: int = 0,
               mirroring: str = "vertical", video=NTSC, fill_page: dict[int, int] | None = None) -> PpuState:
    """tiles: (table, index) -> rows; cells: (ciram page, row, col) -> tile; sprite: (y, tile, attr, x)."""
    chr_data = bytearray(CHR_SIZE)
    for (table, index), rows in (tiles if tiles is not None else {(0, 1): SOLID, (1, 1): SOLID}).items():
        chr_data[table * 0x1000 + index * 16: table * 0x1000 + index * 16 + 16] = tile_bytes(rows)
    ciram = bytearray(CIRAM_SIZE)
    for page, tile in (fill_page or {}).items():
        ciram[page * 0x400: page * 0x400 + 960] = bytes([tile]) * 960
    for (page, row, col), tile in (cells or {}).items():
        ciram[page * 0x400 + row * 32 + col] = tile
    oam = bytearray([0xFF]) * OAM_SIZE
    for number, entry in enumerate([sprite, *others]):
        oam[number * 4: number * 4 + 4] = bytes(entry)
    return PpuState(ctrl=ctrl, mask=mask, scroll_x=scroll_x, scroll_y=scroll_y, mirroring=mirroring, video=video,
                    oam=bytes(oam), chr=bytes(chr_data), ciram=bytes(ciram))
