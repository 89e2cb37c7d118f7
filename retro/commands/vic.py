"""`retro vic`: run a VIC-II scene through the collision model, describe its latches, draw the overlaps."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from retro.chips.vic.constants import (
    IRQ_ANY,
    IRQ_RASTER,
    IRQ_SPRITE_BACKGROUND,
    IRQ_SPRITE_SPRITE,
    REG_SPRITE_Y0,
    SPRITE_COUNT,
    X_BITS_MASK,
    Y_COMPARE_MASK,
)
from retro.chips.vic.model import LatchReport, frame_collisions, run_frames
from retro.chips.vic.sprite_registers import set_sprite_x, sprite_x
from retro.chips.palettes import C64_DEFAULT_PALETTE, PALETTES
from retro.errors import InputError
from retro.fileio import all_or_nothing, file_option
from retro.numbers import parse_int
from retro.scenes.vic import VicScene, load
import argparse
from retro.commands import options

MAX_SCALE = 8
C64_PALETTES = tuple(name for name in PALETTES if name.startswith("c64-"))
MAX_FRAMES = 10_000  # each moving frame is a full collision pass (about a millisecond)


@dataclass
class VicRun:
    scene: VicScene
    report: LatchReport
    png: Path | None = None
    pixels: bool = False  # list every overlap pixel in the answers
    per_frame: list[dict] | None = None  # with moving sprites and --frames N: what each frame showed


@all_or_nothing
def vic(path: str | Path, *, frames: int | str = 1, png: str | Path | None = None, scale: int | str = 2,
        palette: str = C64_DEFAULT_PALETTE, pixels: bool = False) -> VicRun:
    """Load a scene, compute the latches after `frames` frames, optionally write the overlap PNG."""
    frames = parse_int(frames, field="--frames", lo=1, hi=MAX_FRAMES)
    scale = parse_int(scale, field="--scale", lo=1, hi=MAX_SCALE)
    if palette not in C64_PALETTES:
        raise InputError(f"--palette: {palette!r} is not a C64 palette (known: {', '.join(C64_PALETTES)})")
    file_option(png, "--png")
    scene = load(path)
    per_frame = None
    if frames > 1 and any(spec.velocity != (0, 0) for spec in scene.sprites):
        per_frame, state = moving_frames(scene, frames)
        report = run_frames(state, 1)
        report = replace(report, frames=frames)
    else:
        report = run_frames(scene.state, frames)
    written = None
    if png is not None:
        from retro.render.images import save_png
        from retro.render.vic_image import overlap_image

        written = save_png(overlap_image(scene.state, report.collisions, scale, palette), png)
    return VicRun(scene, report, written, pixels, per_frame)


def moved_registers(scene: VicScene, frame: int) -> bytes:
    """The scene's registers with every sprite moved by `frame` times its velocity (X wraps at 512,
    Y at 256: the registers' widths)."""
    registers = bytearray(scene.registers)
    for spec in scene.sprites:
        dx, dy = spec.velocity
        if not (dx or dy):
            continue
        n = spec.index
        set_sprite_x(registers, n, (sprite_x(registers, n) + frame * dx) % (X_BITS_MASK + 1))
        registers[REG_SPRITE_Y0 + 2 * n] = (registers[REG_SPRITE_Y0 + 2 * n] + frame * dy) & Y_COMPARE_MASK
    return bytes(registers)


def moving_frames(scene: VicScene, frames: int) -> tuple[list[dict], object]:
    """Frame by frame, sprites moved by their velocity: what a program that reads $D01E and $D01F
    once per frame, after the frame is drawn (clearing them), sees, and where each was first set.
    Returns the records and the last frame's state."""
    records = []
    state = scene.state
    for frame in range(frames):
        state = scene.state.with_registers(moved_registers(scene, frame))
        events = frame_collisions(state)
        records.append({"frame": frame, "d01e": events.d01e, "d01f": events.d01f,
                        "first": {"d01e": _first(events.first_ss), "d01f": _first(events.first_sb)},
                        "pairs": [list(p) for p in events.pairs]})
    return records, state


def _first(position: tuple[int, int] | None) -> dict | None:
    return None if position is None else {"line": position[0], "x": position[1]}


def _box(lines, xs) -> dict:
    return {"line_min": int(lines.min()), "line_max": int(lines.max()), "x_min": int(xs.min()), "x_max": int(xs.max())}


def overlap_pairs(run: VicRun) -> list[dict]:
    """Each pair of sprites whose opaque pixels meet: how many places they share and where (raster
    lines and X coordinates). A place where three sprites meet counts for each of their pairs."""
    c = run.report.collisions
    if not c.ss_pixels[0].size:
        return []
    out = []
    for a, b in run.report.pairs:
        lines, xs = c.pair_pixels(a, b)
        out.append({"sprites": [a, b], "pixels": int(lines.size), "box": _box(lines, xs),
                    **({"at": _pixel_list(lines, xs)} if run.pixels else {})})
    return out


def background_overlaps(run: VicRun) -> list[dict]:
    """Each sprite whose opaque pixels meet foreground graphics: how many, and where."""
    c = run.report.collisions
    out = []
    for n in range(SPRITE_COUNT):
        lines, xs = c.background_pixels(n)
        if lines.size:
            out.append({"sprite": n, "pixels": int(lines.size), "box": _box(lines, xs),
                        **({"at": _pixel_list(lines, xs)} if run.pixels else {})})
    return out


def _pixel_list(lines, xs) -> list[list[int]]:
    """[[raster line, X], ...] in beam order."""
    order = np.lexsort((xs, lines))
    return [[int(lines[i]), int(xs[i])] for i in order]


def as_json(run: VicRun) -> dict:
    """The object `retro vic --json` prints (its keys are a contract)."""
    r = run.report
    out = {"d01e": r.d01e, "d01f": r.d01f, "d019": r.d019,
           "first": {"d01e": _first(r.first_d01e), "d01f": _first(r.first_d01f)},
           "pairs": overlap_pairs(run), "background": background_overlaps(run)}
    if run.per_frame is not None:
        out["frames"] = run.per_frame
    return out


def _sprites(bits: int) -> str:
    members = [str(n) for n in range(SPRITE_COUNT) if bits >> n & 1]
    return "sprites " + ", ".join(members) if members else "no sprite"


def _where(position: tuple[int, int] | None) -> str:
    return "" if position is None else f"; first set on raster line {position[0]} at X {position[1]}"


def lines(run: VicRun) -> list[str]:
    r = run.report
    video = run.scene.state.video
    d019_sources = [name for bit, name in ((IRQ_SPRITE_SPRITE, "sprite-sprite"),
                                           (IRQ_SPRITE_BACKGROUND, "sprite-background"),
                                           (IRQ_RASTER, "raster compare")) if r.d019 & bit]
    pairs = ", ".join(f"{p['sprites'][0]}+{p['sprites'][1]} ({p['pixels']} px, lines {p['box']['line_min']}-"
                      f"{p['box']['line_max']}, X {p['box']['x_min']}-{p['box']['x_max']})"
                      for p in overlap_pairs(run)) or "none"
    background = ", ".join(f"{b['sprite']} ({b['pixels']} px)" for b in background_overlaps(run)) or "none"
    lines = [f"{run.scene.source}: {video.name.upper()} ({video.chip}), after {r.frames} frame(s)",
             f"$D01E = ${r.d01e:02X} %{r.d01e:08b}  sprite-sprite: {_sprites(r.d01e)}{_where(r.first_d01e)}",
             f"$D01F = ${r.d01f:02X} %{r.d01f:08b}  sprite-background: {_sprites(r.d01f)}{_where(r.first_d01f)}",
             f"$D019 = ${r.d019:02X} %{r.d019:08b}  latched: {', '.join(d019_sources) or 'nothing'}"
             f"{'; IRQ line active (bit 7)' if r.d019 & IRQ_ANY else ''}",
             f"overlapping sprite pairs (not visible to a program): {pairs}",
             f"sprites over foreground graphics: {background}"]
    if run.pixels:
        lines += _pixel_lines(run)
    if run.per_frame is not None:
        lines += _per_frame_lines(run.per_frame)
    if run.png is not None:
        lines.append(f"wrote {run.png}")
    return lines


def _pixel_lines(run: VicRun) -> list[str]:
    lines = []
    for p in overlap_pairs(run):
        lines.append(f"pixels of {p['sprites'][0]}+{p['sprites'][1]} (line, X): "
                     + " ".join(f"{line},{x}" for line, x in p["at"]))
    for b in background_overlaps(run):
        lines.append(f"pixels of {b['sprite']} over graphics (line, X): "
                     + " ".join(f"{line},{x}" for line, x in b["at"]))
    return lines


def _per_frame_lines(per_frame: list[dict]) -> list[str]:
    """The frames of a moving scene that collided (the first 20)."""
    hits = [f for f in per_frame if f["d01e"] or f["d01f"]]
    lines = [f"moving sprites, {len(per_frame)} frames read once each (clear on read): "
             f"{len(hits)} frame(s) with a collision" + (f", the first in frame {hits[0]['frame']}" if hits else "")]
    for f in hits[:20]:
        lines.append(f"  frame {f['frame']}: $D01E = ${f['d01e']:02X}, $D01F = ${f['d01f']:02X}"
                     + (f", pairs {', '.join(f'{a}+{b}' for a, b in f['pairs'])}" if f["pairs"] else ""))
    if len(hits) > 20:
        lines.append(f"  ... {len(hits) - 20} more (--json lists every frame)")
    return lines


# The command line: this command's options and how it runs from them.

HELP = "predict the VIC-II collision registers for a scene; draw the overlaps"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", metavar="SCENE.toml", help="a VIC-II scene file (docs/vic.md)")
    p.add_argument("--frames", default="1", metavar="N",
                   help=f"frames to run (default 1, at most {MAX_FRAMES:,}): sprites with a velocity move each "
                        "frame, and each frame's latches are reported as a program reading them once a frame sees them")
    p.add_argument("--json", action="store_true", help="print one JSON object: d01e, d01f, d019, first, pairs, "
                                                       "background")
    p.add_argument("--pixels", action="store_true", help="list every overlap pixel (raster line, X) of each pair "
                                                         "and each sprite over graphics")
    p.add_argument("--png", metavar="OUT.png", help="write the frame with the overlaps marked")
    options.scale(p, "image", MAX_SCALE)
    p.add_argument("--palette", default=C64_DEFAULT_PALETTE,
                   help=f"{' or '.join(C64_PALETTES)} (default: {C64_DEFAULT_PALETTE})")


def main(args: argparse.Namespace) -> int:
    result = vic(args.scene, frames=args.frames, png=args.png, scale=args.scale, palette=args.palette,
                 pixels=args.pixels)
    options.show(lines, as_json if args.json else None, result)
    return 0
