"""`retro parry`: the parry pipeline (retro.geometry.parry) on a scripted input, drawn as a GIF and PNGs.

The script format: FRAME:ACTION tokens separated by spaces, commas or new lines, `#` starting a
comment; `@FILE` reads the tokens from a file."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from retro.errors import InputError
from retro.fileio import all_or_nothing, read_text
from retro.geometry.parry import ACTIONS, DEFAULT_FRAMES, MAX_FRAMES, Event, FrameState, events_of, simulate
from retro.numbers import parse_int
from retro.render.parry import write_parry
import argparse
from retro.commands import options

DEFAULT_OUT = "retro-out/parry"
DEFAULT_SCRIPT = "40:parry 106:parry 150:left 170:stop 192:parry"
MAX_SCRIPT_BYTES = 1 << 20  # a FRAME:ACTION for every frame of the longest run is about 120 KB


@dataclass(frozen=True)
class ParryRun:
    script: str  # the script text that ran
    source: str  # where it came from: "built-in script", "--script" or the file's name
    states: list[FrameState]
    events: list[Event]
    files: list[Path]


def parse_script(text: str, source: str = "script") -> list[tuple[int, str]]:
    """Parse 'FRAME:ACTION' tokens separated by spaces, commas or new lines ('#' starts a comment).
    FRAME is any number parse_int accepts; ACTION is parry, left, right or stop. Returns the
    (frame, action) list sorted by frame (stable). Errors name the source, line and token."""
    steps: list[tuple[int, str]] = []
    for line_no, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0]
        for token in re.split(r"[\s,]+", line.strip()):
            if not token:
                continue
            where = f"{source}:{line_no}: {token!r}" if "\n" in text.strip() else f"{source}: {token!r}"
            frame_text, sep, action = token.partition(":")
            if not sep:
                raise InputError(f"{where}: expected FRAME:ACTION, e.g. 40:parry")
            action = action.lower()
            if action not in ACTIONS:
                raise InputError(f"{where}: unknown action {action!r} (expected {', '.join(ACTIONS)})")
            frame = parse_int(frame_text, field=f"{where}: frame", lo=0, hi=MAX_FRAMES - 1)
            steps.append((frame, action))
    steps.sort(key=lambda s: s[0])
    return steps


def load_script(spec: str | None, frames: int = DEFAULT_FRAMES) -> tuple[str, str]:
    """(script text, source name): '@FILE' reads a script file, anything else is the script itself,
    None gives the built-in script, cut to the inputs that fall within `frames`."""
    if spec is None:
        kept = [token for frame, token in zip(parse_script(DEFAULT_SCRIPT), DEFAULT_SCRIPT.split())
                if frame[0] < frames]
        return " ".join(kept), "built-in script"
    if not spec.strip():  # not the built-in script: a shell variable left empty
        raise InputError("--script: empty: give FRAME:ACTION inputs or @FILE, or leave --script out for the "
                         "built-in script")
    if spec.startswith("@"):
        path = spec[1:]
        return read_text(path, "parry script", MAX_SCRIPT_BYTES), path
    return spec, "--script"


@all_or_nothing
def parry(script: str | None = None, *, out: str | Path = DEFAULT_OUT, frames: int | str = DEFAULT_FRAMES) -> ParryRun:
    """Simulate `frames` frames under the script (text, '@FILE', or None for the built-in one) and
    write parry.gif, one PNG per event frame and parry_events.txt into `out`."""
    frames = parse_int(frames, field="--frames", lo=1, hi=MAX_FRAMES)
    text, source = load_script(script, frames)
    states = simulate(parse_script(text, source), frames, source=source)
    files = write_parry(out, states)
    return ParryRun(text, source, states, events_of(states), files)


def lines(run: ParryRun) -> list[str]:
    out = [f"frame {event.frame:4d}  {event.kind}" for event in run.events]
    return out + [f"wrote {len(run.files)} files to {run.files[0].parent} (parry.gif, one PNG per event frame, "
                  "parry_events.txt)"]


# The command line: this command's options and how it runs from them.

HELP = "run the Sekiro-style parry loop on a scripted input; writes a GIF and PNGs"
PARSER = {"description": "Script: FRAME:ACTION tokens (ACTION = parry, left, right or stop), e.g. '40:parry 90:left "
                         "110:stop'; '@FILE' reads them from a file (one or more per line, '#' starts a comment)."}


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--script", metavar="SCRIPT", help="input script or @FILE (default: a built-in script)")
    options.out(p, DEFAULT_OUT)
    p.add_argument("--frames", default=str(DEFAULT_FRAMES), metavar="N",
                   help=f"frames to simulate (default: {DEFAULT_FRAMES}, at most {MAX_FRAMES:,})")


def main(args: argparse.Namespace) -> int:
    result = parry(args.script, out=args.out, frames=args.frames)
    options.show(lines, None, result)
    return 0
