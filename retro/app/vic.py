"""`retro vic` as functions: run a scene through the collision model, describe it, draw it.

The CLI and the demo call these; they only parse arguments and print.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.chips.vic.constants import (
    IRQ_ANY,
    IRQ_RASTER,
    IRQ_SPRITE_BACKGROUND,
    IRQ_SPRITE_SPRITE,
    SPRITE_COUNT,
)
from retro.chips.vic.model import LatchReport, run_frames
from retro.errors import InputError
from retro.render.palette import C64_DEFAULT_PALETTE
from retro.scenes.vic import VicScene, load

DEMO_SCENE = "vic_two_balls.toml"
MAX_SCALE = 8
MAX_FRAMES = 1_000_000


@dataclass
class VicRun:
    scene: VicScene
    report: LatchReport
    png: Path | None = None


def run_scene(path: str | Path, frames: int = 1, png: str | Path | None = None, scale: int = 2,
              palette_name: str = C64_DEFAULT_PALETTE) -> VicRun:
    """Load a scene, compute the latches after `frames` frames, optionally write the overlap PNG."""
    if not 1 <= frames <= MAX_FRAMES:
        raise InputError(f"--frames: {frames} is out of range 1..{MAX_FRAMES}")
    if not 1 <= scale <= MAX_SCALE:
        raise InputError(f"--scale: {scale} is out of range 1..{MAX_SCALE}")
    scene = load(path)
    report = run_frames(scene.state, frames)
    written = None
    if png is not None:
        from retro.render.images import save_png
        from retro.render.vic_image import overlap_image

        written = save_png(overlap_image(scene.state, report.collisions, scale, palette_name), png)
    return VicRun(scene, report, written)


def _first(position: tuple[int, int] | None) -> dict | None:
    return None if position is None else {"line": position[0], "x": position[1]}


def report_json(run: VicRun) -> dict:
    r = run.report
    return {"d01e": r.d01e, "d01f": r.d01f, "d019": r.d019,
            "first": {"d01e": _first(r.first_d01e), "d01f": _first(r.first_d01f)}}


def _sprites(bits: int) -> str:
    members = [str(n) for n in range(SPRITE_COUNT) if bits >> n & 1]
    return "sprites " + ", ".join(members) if members else "no sprite"


def _where(position: tuple[int, int] | None) -> str:
    return "" if position is None else f"; first set on raster line {position[0]} at X {position[1]}"


def report_lines(run: VicRun) -> list[str]:
    r = run.report
    video = run.scene.state.video
    d019_sources = [name for bit, name in ((IRQ_SPRITE_SPRITE, "sprite-sprite"),
                                           (IRQ_SPRITE_BACKGROUND, "sprite-background"),
                                           (IRQ_RASTER, "raster compare")) if r.d019 & bit]
    pairs = ", ".join(f"{a}+{b}" for a, b in r.pairs) or "none"
    lines = [f"{run.scene.source}: {video.name.upper()} ({video.chip}), after {r.frames} frame(s)",
             f"$D01E = ${r.d01e:02X} %{r.d01e:08b}  sprite-sprite: {_sprites(r.d01e)}{_where(r.first_d01e)}",
             f"$D01F = ${r.d01f:02X} %{r.d01f:08b}  sprite-background: {_sprites(r.d01f)}{_where(r.first_d01f)}",
             f"$D019 = ${r.d019:02X} %{r.d019:08b}  latched: {', '.join(d019_sources) or 'nothing'}"
             f"{'; IRQ line active (bit 7)' if r.d019 & IRQ_ANY else ''}",
             f"overlapping sprite pairs (not visible to a program): {pairs}"]
    if run.png is not None:
        lines.append(f"wrote {run.png}")
    return lines
