"""`retro nes SCENE [--json] [--png OUT.png] [--scale K]`: the sprite-zero hit of an NES scene."""

from __future__ import annotations

import argparse
import json

from retro.app.nes import MAX_SCALE, check_scene, describe
from retro.numbers import parse_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("nes", help="predict the NES sprite-zero hit ($2002 bit 6) of a scene: pixel, line, dot")
    p.add_argument("scene", metavar="SCENE.toml")
    p.add_argument("--json", action="store_true", help="print one JSON object: hit, line, dot, x, dots_after_vblank, cpu_cycles_after_vblank")
    p.add_argument("--png", metavar="OUT.png", help="write a picture of the frame and sprite 0")
    p.add_argument("--scale", default="2", metavar="K", help=f"integer picture scale 1-{MAX_SCALE} (default 2)")
    p.set_defaults(func=cmd_nes)


def cmd_nes(args: argparse.Namespace) -> int:
    scale = parse_int(args.scale, field="--scale", lo=1, hi=MAX_SCALE)
    result = check_scene(args.scene, png=args.png, scale=scale)
    print(json.dumps(result.as_json()) if args.json else describe(result))
    if args.png and not args.json:
        print(f"wrote {args.png}")
    return 0
