"""`retro parry [--script SCRIPT|@FILE] [--out DIR] [--frames N]`: the parry pipeline example."""

from __future__ import annotations

import argparse

from retro.geometry.parry import DEFAULT_FRAMES, MAX_FRAMES
from retro.numbers import parse_int
from retro.render.parry import load_script, write_parry

DEFAULT_OUT = "retro-out/parry"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("parry", help="run the Sekiro-style parry loop on a scripted input; writes a GIF and PNGs",
                       description="Script: FRAME:ACTION tokens (ACTION = parry, left, right or stop), "
                                   "e.g. '40:parry 90:left 110:stop'; '@FILE' reads them from a file "
                                   "(one or more per line, '#' starts a comment).")
    p.add_argument("--script", metavar="SCRIPT", help="input script or @FILE (default: a built-in script)")
    p.add_argument("--out", default=DEFAULT_OUT, metavar="DIR", help=f"output folder (default: {DEFAULT_OUT})")
    p.add_argument("--frames", default=str(DEFAULT_FRAMES), metavar="N",
                   help=f"frames to simulate (default: {DEFAULT_FRAMES})")
    p.set_defaults(func=cmd_parry)


def cmd_parry(args: argparse.Namespace) -> int:
    frames = parse_int(args.frames, field="--frames", lo=1, hi=MAX_FRAMES)
    text, source = load_script(args.script, frames)
    run = write_parry(args.out, text, frames, source=source)
    for event in run.events:
        print(f"frame {event.frame:4d}  {event.kind}")
    print(f"wrote {len(run.files)} files to {args.out} (parry.gif, one PNG per event frame, parry_events.txt)")
    return 0
