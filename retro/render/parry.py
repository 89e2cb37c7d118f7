"""Pictures of the parry pipeline: an animated GIF of every frame plus one PNG per event frame.

Each frame shows the arena with both pentagons, their AABBs, the player's padded AABB (yellow while
the parry window is open), the MTV arrow on a contact, a status line, and a timeline of the whole
run underneath (window spans in yellow, events as coloured ticks, the current frame in white).
"""

from __future__ import annotations

import io
from pathlib import Path

from PIL import Image, ImageDraw

from retro.fileio import output_folder, write_atomic
from retro.geometry.parry import FrameState, ParryParams, events_of
from retro.render.images import label_font, save_png

SCALE = 2
STATUS_HEIGHT = 22
TIMELINE_HEIGHT = 46
GIF_FRAME_MS = 40
BANNER_FRAMES = 18
ARROW_LENGTH = 36  # screen pixels  # how long "PARRY" / "HIT" stays on screen after the event

# Palette indices (the frames are drawn straight into a paletted image: no quantising for the GIF).
BACKGROUND, GROUND, PLAYER_FILL, PLAYER_LINE, ENEMY_FILL, ENEMY_LINE, BOX, PAD_CLOSED, PAD_OPEN, TEXT, \
    PARRY, HIT, ARROW, ARMED, GREY = range(15)
PALETTE = [(18, 18, 28), (60, 60, 76), (36, 78, 150), (130, 185, 255), (130, 36, 40), (255, 120, 110),
           (120, 120, 130), (96, 92, 60), (255, 210, 60), (230, 230, 230), (90, 230, 120), (255, 80, 80),
           (255, 255, 255), (110, 240, 240), (150, 150, 150)]
EVENT_COLOURS = {"window": PAD_OPEN, "press": ARMED, "whiff": GREY, "parry": PARRY, "hit": HIT, "expired": GREY}


def _poly(draw: ImageDraw.ImageDraw, points, fill: int, outline: int) -> None:
    draw.polygon([(x * SCALE, y * SCALE) for x, y in points], fill=fill, outline=outline)


def _rect(draw: ImageDraw.ImageDraw, lo, hi, colour: int) -> None:
    draw.rectangle([lo[0] * SCALE, lo[1] * SCALE, hi[0] * SCALE, hi[1] * SCALE], outline=colour)


def _bounds(points) -> tuple[tuple[float, float], tuple[float, float]]:
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    return (min(xs), min(ys)), (max(xs), max(ys))


def render_frame(states: list[FrameState], index: int, params: ParryParams = ParryParams()) -> Image.Image:
    """One frame of the run as a paletted image."""
    width, height = int(params.arena[0] * SCALE), int(params.arena[1] * SCALE)
    image = Image.new("P", (width, STATUS_HEIGHT + height + TIMELINE_HEIGHT), BACKGROUND)
    image.putpalette([c for rgb in PALETTE for c in rgb])
    state = states[index]
    small = label_font(12)
    window_open = state.in_window or state.window_left > 0
    image.paste(_arena(states, index, params, width, height, window_open), (0, STATUS_HEIGHT))
    top = ImageDraw.Draw(image)
    top.text((6, 4), _status(state, params, window_open), fill=TEXT, font=small)
    _timeline(top, states, state, STATUS_HEIGHT + height + 4, width, small)
    return image


def _arena(states: list[FrameState], index: int, params: ParryParams, width: int, height: int,
           window_open: bool) -> Image.Image:
    """The fighters, their boxes, the parry pad, the push of a contact and the banner of an event."""
    state = states[index]
    small, big = label_font(12), label_font(26)
    arena = Image.new("P", (width, height), BACKGROUND)
    draw = ImageDraw.Draw(arena)
    ground = params.arena[1] / 2 + params.radius
    draw.line([(0, ground * SCALE), (width, ground * SCALE)], fill=GROUND, width=1)
    _rect(draw, *state.padded_box, PAD_OPEN if window_open else PAD_CLOSED)
    _poly(draw, state.player, PLAYER_FILL, PLAYER_LINE)
    _poly(draw, state.enemy, ENEMY_FILL, ENEMY_LINE)
    _rect(draw, *_bounds(state.player), BOX)
    _rect(draw, *_bounds(state.enemy), BOX)
    if state.contact is not None:
        (ax, ay), depth = state.contact
        cx = sum(p[0] for p in state.player) / len(state.player)
        cy = sum(p[1] for p in state.player) / len(state.player)
        # The push itself is a pixel or two: draw the direction at a fixed length so it reads.
        tip = (cx * SCALE + ax * ARROW_LENGTH, cy * SCALE + ay * ARROW_LENGTH)
        draw.line([(cx * SCALE, cy * SCALE), tip], fill=ARROW, width=2)
        draw.ellipse([tip[0] - 3, tip[1] - 3, tip[0] + 3, tip[1] + 3], fill=ARROW)
        top_y = min(p[1] for p in state.player) * SCALE
        draw.text((cx * SCALE, top_y - 6), f"MTV depth {depth:.2f}px", fill=ARROW, font=small, anchor="mb")
    recent = [e for s in states[max(0, index - BANNER_FRAMES + 1):index + 1] for e in s.events
              if e.kind in ("parry", "hit")]
    if recent:
        word = recent[-1].kind.upper() + "!"
        draw.text((width // 2, 14), word, fill=EVENT_COLOURS[recent[-1].kind], font=big, anchor="mt")
    return arena


def _status(state: FrameState, params: ParryParams, window_open: bool) -> str:
    status = f"frame {state.frame:3d}"
    kinds = [e.kind for e in state.events]
    if "parry" in kinds:
        status += "   PARRY: SAT contact inside the window with the parry armed"
    elif "hit" in kinds:
        status += "   HIT: SAT contact " + ("inside the window, parry not pressed" if state.in_window
                                          else "with no parry window open")
    elif state.window_left or window_open:
        status += f"   parry window: {state.window_left:2d} of {params.window_frames} frames left"
        if state.armed:
            status += "   parry armed"
    else:
        status += "   window closed"
    others = [k for k in kinds if k not in ("parry", "hit")]
    if others:
        status += "   event: " + ", ".join(others)
    return status


def _window_spans(states: list[FrameState]) -> list[tuple[int, int]]:
    """(opened, closed) frames of every parry window."""
    opened = None
    spans = []
    for s in states:
        for e in s.events:
            if e.kind == "window":
                opened = e.frame
            elif e.kind in ("parry", "hit", "expired") and opened is not None:
                spans.append((opened, e.frame))
                opened = None
    if opened is not None:
        spans.append((opened, states[-1].frame))
    return spans


def _timeline(top: ImageDraw.ImageDraw, states: list[FrameState], state: FrameState, y0: int, width: int,
              small) -> None:
    """One column per frame, scaled to the width: windows, events, the current frame, a legend."""
    step = width / len(states)
    for a, b in _window_spans(states):
        top.rectangle([a * step, y0 + 8, (b + 1) * step, y0 + 14], fill=PAD_CLOSED)
    for e in events_of(states):
        x = (e.frame + 0.5) * step
        top.line([(x, y0 + 2), (x, y0 + 20)], fill=EVENT_COLOURS[e.kind], width=2)
    x = (state.frame + 0.5) * step
    top.polygon([(x, y0 + 21), (x - 4, y0 + 26), (x + 4, y0 + 26)], fill=ARROW)
    legend_x = 6
    for label, colour in (("timeline:", TEXT), ("window", PAD_OPEN), ("press", ARMED), ("parry", PARRY),
                          ("hit", HIT), ("whiff / expired", GREY), ("now", ARROW)):
        top.text((legend_x, y0 + 28), label, fill=colour, font=small)
        legend_x += int(top.textlength(label, font=small)) + 12


def write_parry(out_dir: str | Path, states: list[FrameState], params: ParryParams = ParryParams()) -> list[Path]:
    """Write parry.gif (every frame), parry_FFF_EVENT.png for each event frame and parry_events.txt
    into out_dir; returns the files in that order."""
    out = output_folder(out_dir)
    images = [render_frame(states, i, params) for i in range(len(states))]
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], duration=GIF_FRAME_MS,
                   loop=0, optimize=False, disposal=1)
    files = [write_atomic(out / "parry.gif", buffer.getvalue())]
    for state in states:
        if state.events:
            kinds = "_".join(e.kind for e in state.events)
            files.append(save_png(images[state.frame].convert("RGB"), out / f"parry_{state.frame:03d}_{kinds}.png"))
    text = "".join(f"{e.frame} {e.kind}\n" for e in events_of(states))
    files.append(write_atomic(out / "parry_events.txt", text))
    return files
