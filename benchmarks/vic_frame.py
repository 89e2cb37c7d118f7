"""VIC-II frame model speed: numpy masks vs a straightforward per-pixel Python loop, one run.

Scene: 8 enabled sprites (mixed hires/multicolor, some expanded) over a full screen of text (every
cell a non-blank character). Prints frames per second of both, the ratio, and ms per frame, and
checks that both give the same $D01E/$D01F. Goal (issue 3): >= 100x the loop, < 1 ms per frame.

    python benchmarks/vic_frame.py [--loop-frames N]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from retro.chips.vic import constants as C  # noqa: E402
from retro.chips.vic.model import frame_collisions, sprite_rows  # noqa: E402
from retro.scenes.vic import parse  # noqa: E402
from retro.sprites import decode  # noqa: E402

SPRITES_DIR = Path(__file__).resolve().parent.parent / "sprites"


def bench_scene():
    rng = np.random.default_rng(64)
    names = ["ball", "ring", "ship", "pentagon", "mc_ball", "lshape", "mc_gem", "bar"]
    sprites = []
    for n, name in enumerate(names):
        sprites.append({"index": n, "x": int(60 + 28 * n), "y": int(60 + 17 * n), "color": n + 1,
                        "multicolor": name.startswith("mc_"), "expand_x": n == 2, "expand_y": n == 3,
                        "file": str(SPRITES_DIR / f"{name}.spr")})
    glyphs = {str(code): [int(v) for v in rng.integers(0, 256, 8)] for code in range(1, 64)}
    cells = [{"col": c, "row": r, "value": int(rng.integers(1, 64))} for r in range(25) for c in range(40)]
    doc = {"chip": "vic-ii", "video": "pal", "registers": {"$d011": 0x1B, "$d016": 0xD8},
           "sprite": sprites,
           "memory": {"screen": {"fill": 1, "cells": cells},
                      "color": {"fill": 1, "cells": [{"col": c, "row": 3, "value": 9} for c in range(40)]},
                      "charset": glyphs}}
    return parse(doc, "benchmark scene")


def loop_frame(state) -> tuple[int, int]:
    """The obvious implementation: visit every pixel of the frame, ask every sprite, decode the text."""
    video, regs, mem = state.video, state.registers, state.memory
    d011, d016 = regs[C.REG_CONTROL1], regs[C.REG_CONTROL2]
    yscroll, xscroll = d011 & 7, d016 & 7
    top, bottom = C.WINDOW_LINES[1 if d011 & C.CONTROL1_RSEL else 0]
    mcm = bool(d016 & C.CONTROL2_MCM)
    shapes = []
    for n in range(8):
        x = regs[2 * n] | ((regs[0x10] >> n) & 1) << 8
        mc = bool(regs[0x1C] >> n & 1)
        ex = bool(regs[0x1D] >> n & 1)
        pixels = decode(state.sprite_data[n], mc)
        rows = sprite_rows(video, regs[2 * n + 1], bool(regs[0x17] >> n & 1))
        shapes.append((x, mc, ex, pixels.tolist(), rows.tolist(), bool(regs[0x15] >> n & 1)))
    d01e = d01f = 0
    for line in range(video.lines):
        for x in range(video.x_positions):
            hits = 0
            for n, (sx, mc, ex, pixels, rows, on) in enumerate(shapes):
                row = rows[line]
                if not on or row < 0 or sx >= video.x_positions:
                    continue
                i = (x - sx) % video.x_positions
                if ex:
                    i //= 2
                if i >= 24:
                    continue
                if (pixels[row][i // 2] if mc else pixels[row][i]):
                    hits |= 1 << n
            if not hits:
                continue
            if hits & (hits - 1):
                d01e |= hits
            if top <= line <= bottom:
                offset = line - 48 - yscroll
                p = x - 24 - xscroll
                if 0 <= p < 320:
                    if 0 <= offset < 200:
                        cell = offset // 8 * 40 + p // 8
                        byte = int(mem.charset[int(mem.screen[cell]) * 8 + offset % 8])
                        multi = mcm and bool(mem.color[cell] & 8)
                    else:
                        byte, multi = mem.idle, False
                    k = p % 8
                    if (byte >> (7 - (k & 6)) if multi else byte >> (7 - k)) & 1:
                        d01f |= hits
    return d01e, d01f


def moved(state, pixels: int):
    """The state with every sprite's 9-bit X advanced by `pixels` (wrapping at 512)."""
    registers = bytearray(state.registers)
    msb = 0
    for n in range(C.SPRITE_COUNT):
        x = (state.sprite_x(n) + pixels) & C.X_BITS_MASK
        registers[C.REG_SPRITE_X0 + 2 * n] = x & 0xFF
        msb |= (x >> 8) << n
    registers[C.REG_SPRITE_X_MSB] = msb
    return state.with_registers(bytes(registers))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--loop-frames", type=int, default=3)  # one slow frame is too noisy to time
    parser.add_argument("--model-frames", type=int, default=300)
    args = parser.parse_args()
    state = bench_scene().state
    frame_collisions(state)  # warm the caches (sprite row tables, shapes), as a running device would be

    start = time.perf_counter()
    for _ in range(args.model_frames):
        result = frame_collisions(state)
    model_seconds = (time.perf_counter() - start) / args.model_frames

    # The same scene with every sprite one pixel further right each frame: nothing cached per sprite
    # placement can be reused, as in a game where everything moves.
    moving = [moved(state, frame) for frame in range(1, args.model_frames + 1)]
    start = time.perf_counter()
    for frame_state in moving:
        frame_collisions(frame_state)
    moving_seconds = (time.perf_counter() - start) / args.model_frames

    start = time.perf_counter()
    for _ in range(args.loop_frames):
        loop_result = loop_frame(state)
    loop_seconds = (time.perf_counter() - start) / args.loop_frames

    same = (result.d01e, result.d01f) == loop_result
    print(f"scene: 8 sprites over a full text screen (PAL, {state.video.lines} lines x {state.video.x_positions} X)")
    print(f"numpy model : {1 / model_seconds:10.1f} frames/s  ({model_seconds * 1e3:.3f} ms per frame)")
    print(f"Python loop : {1 / loop_seconds:10.3f} frames/s  ({loop_seconds * 1e3:.1f} ms per frame)")
    print(f"ratio       : {loop_seconds / model_seconds:10.0f}x")
    print(f"moving      : {1 / moving_seconds:10.1f} frames/s  ({moving_seconds * 1e3:.3f} ms per frame, every sprite "
          f"1 px further each frame): {loop_seconds / moving_seconds:.0f}x the loop")
    print(f"same result : {same} ($D01E=${result.d01e:02X} $D01F=${result.d01f:02X}; "
          f"loop ${loop_result[0]:02X} ${loop_result[1]:02X})")
    if not same:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
