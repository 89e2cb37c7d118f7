"""Scene builders for the VIC-II tests: documents in the scene-file format, parsed by the real parser."""

from __future__ import annotations

from retro.chips.vic.model import run_frames
from retro.scenes.vic import parse

HIRES_WIDTH, MC_WIDTH, HEIGHT = 24, 12, 21


def rows_with(pixels, multicolor: bool = False, value: str = "#") -> list[str]:
    """21 row strings with the given (row, col) pixels set (value '1'/'2'/'3' for multicolor)."""
    width = MC_WIDTH if multicolor else HIRES_WIDTH
    grid = [["."] * width for _ in range(HEIGHT)]
    for r, c in pixels:
        grid[r][c] = value if multicolor or value != "#" else "#"
    return ["".join(row) for row in grid]


FULL = ["#" * HIRES_WIDTH] * HEIGHT


def sprite(index: int, x: int, y: int, rows=None, **flags) -> dict:
    return {"index": index, "x": x, "y": y, "rows": rows if rows is not None else FULL, **flags}


def scene(*sprites: dict, video: str = "pal", registers: dict | None = None, memory: dict | None = None):
    doc = {"chip": "vic-ii", "video": video, "registers": {"$d011": 0x1B, "$d016": 0xC8, **(registers or {})},
           "sprite": list(sprites)}
    if memory is not None:
        doc["memory"] = memory
    return parse(doc, "test.toml")


def latches(*sprites: dict, **kw):
    return run_frames(scene(*sprites, **kw).state)
