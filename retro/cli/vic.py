"""`retro vic SCENE [--frames N] [--json] [--png OUT.png] [--scale K]`"""

from __future__ import annotations

import argparse
import json

from retro.app.vic import MAX_FRAMES, MAX_SCALE, report_json, report_lines, run_scene
from retro.numbers import parse_int
from retro.chips.palettes import C64_DEFAULT_PALETTE


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("vic", help="predict the VIC-II collision registers for a scene; draw the overlaps")
    p.add_argument("scene", metavar="SCENE.toml", help="a VIC-II scene file (docs/vic.md)")
    p.add_argument("--frames", default="1", metavar="N", help="frames to run (default 1, at most 10,000): sprites with a "
                   "velocity move each frame, and each frame's latches are reported as a program reading them once a frame sees them")
    p.add_argument("--json", action="store_true", help="print one JSON object: d01e, d01f, d019, first, pairs, "
                   "background")
    p.add_argument("--pixels", action="store_true", help="list every overlap pixel (raster line, X) of each pair "
                   "and each sprite over graphics")
    p.add_argument("--png", metavar="OUT.png", help="write the frame with the overlaps marked")
    p.add_argument("--scale", default="2", metavar="K", help=f"integer image scale 1-{MAX_SCALE} (default 2)")
    p.add_argument("--palette", default=C64_DEFAULT_PALETTE, help="c64-pepto (default) or c64-colodore")
    p.set_defaults(func=cmd_vic)


def cmd_vic(args: argparse.Namespace) -> int:
    run = run_scene(args.scene, frames=parse_int(args.frames, field="--frames", lo=1, hi=MAX_FRAMES),
                    png=args.png, scale=parse_int(args.scale, field="--scale", lo=1, hi=MAX_SCALE),
                    palette_name=args.palette, pixels=args.pixels)
    if args.json:
        print(json.dumps(report_json(run)))
    else:
        print("\n".join(report_lines(run)))
    return 0
