"""The parry pipeline (the Sekiro-style combat loop) as a pure, frame-stepped simulation.

Two pentagons: the player on the left, an enemy that spins and lunges from the right. Each frame:

1. Apply the scripted input for this frame (left / right / stop change the walking direction and
   last until changed; parry is a one-frame press).
2. Move both bodies (walking, lunging, knock-back velocity that decays by `friction`).
3. Broad test: when the player's AABB grown by `pad` on every side starts to overlap the enemy's
   AABB, a parry window of `window_frames` frames opens (event "window"). It opens again only after
   the padded boxes have separated.
4. A parry press while the window is open arms the parry (event "press"); a press with no window
   open is wasted (event "whiff").
5. Narrow test: SAT on the two pentagons. On overlap inside the window with the parry armed the
   enemy is deflected ("parry"); otherwise the player takes the blow ("hit"). Either way the
   loser is pushed out along the MTV (by the depth) and knocked back along it, and the window closes.
6. A window that runs out without contact closes with event "expired".

The window covers exactly `window_frames` frames: opened on frame f, a contact on frames
f .. f + window_frames - 1 is inside it.

Pure: `simulate(inputs, frames, params)` returns one FrameState per frame; the script format is
read by retro.commands.parry, pictures are drawn by retro.render.parry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from retro.errors import InputError
from retro.geometry.aabb import aabb_overlap, points_bounds
from retro.geometry.polygon import regular_polygon
from retro.geometry.sat import sat

ACTIONS = ("parry", "left", "right", "stop")
EVENT_KINDS = ("window", "press", "whiff", "parry", "hit", "expired")
MAX_FRAMES = 2_000  # every frame is drawn and held for the GIF (~350 KB each): 2,000 peak at ~750 MB

DEFAULT_FRAMES = 230


@dataclass(frozen=True)
class ParryParams:
    """Tuning of the example (pixels and frames; y grows downwards as on screen)."""

    window_frames: int = 12
    pad: float = 14.0
    radius: float = 18.0
    arena: tuple[float, float] = (320.0, 100.0)
    player_start: float = 90.0
    enemy_start: float = 270.0
    walk_speed: float = 1.5
    lunge_speed: float = 2.5
    spin: float = 0.045          # enemy rotation per frame, radians
    knockback: float = 7.0       # speed given along the MTV to whoever loses
    friction: float = 0.85       # knock-back velocity kept per frame
    recover_frames: int = 24     # frames the enemy backs off after a contact


@dataclass(frozen=True)
class Event:
    frame: int
    kind: str  # one of EVENT_KINDS

    def __str__(self) -> str:
        return f"{self.frame}:{self.kind}"


@dataclass(frozen=True)
class FrameState:
    """Everything a renderer or a test needs about one frame, after the frame was simulated."""

    frame: int
    player: list[tuple[float, float]]
    enemy: list[tuple[float, float]]
    padded_box: tuple[tuple[float, float], tuple[float, float]]
    in_window: bool             # the parry window was open when this frame's contact test ran
    window_left: int            # frames of the window still open after this frame (0 = closed)
    armed: bool                 # parry pressed inside the open window
    contact: tuple[tuple[float, float], float] | None  # SAT (axis, depth) of player vs enemy, before push-out
    events: list[Event] = field(default_factory=list)


def simulate(script: list[tuple[int, str]], frames: int = DEFAULT_FRAMES,
             params: ParryParams = ParryParams(), source: str = "script") -> list[FrameState]:
    """Run the parry loop for `frames` frames under the scripted input: (frame, action) pairs (the
    text format is read by retro.commands.parry). Inputs scheduled at or after `frames` are an error."""
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= MAX_FRAMES:
        raise InputError(f"frames: must be an integer in 1..{MAX_FRAMES}, got {frames!r}")
    steps = sorted(script, key=lambda step: step[0])
    for frame, action in steps:
        if action not in ACTIONS:
            raise InputError(f"{source}: unknown action {action!r} (expected {', '.join(ACTIONS)})")
        if not 0 <= frame < frames:
            raise InputError(f"{source}: {frame}:{action}: frame {frame} is outside 0..{frames - 1} (--frames {frames})")
    inputs: dict[int, list[str]] = {}
    for frame, action in steps:
        inputs.setdefault(frame, []).append(action)

    p = params
    width, height = p.arena
    ground = height / 2
    player = [p.player_start, ground]
    enemy = [p.enemy_start, ground]
    player_vel = [0.0, 0.0]
    enemy_vel = [0.0, 0.0]
    angle = 0.0
    walk = 0
    window = 0
    armed = False
    recovering = 0
    was_padded = False
    out: list[FrameState] = []

    def clamp_x(pos: list[float]) -> None:
        pos[0] = min(max(pos[0], p.radius), width - p.radius)
        pos[1] = min(max(pos[1], p.radius), height - p.radius)

    for f in range(frames):
        events: list[Event] = []
        pressed = False
        for action in inputs.get(f, ()):
            if action == "parry":
                pressed = True
            else:
                walk = {"left": -1, "right": 1, "stop": 0}[action]

        # 2. motion
        player[0] += walk * p.walk_speed + player_vel[0]
        player[1] += player_vel[1]
        player_vel = [v * p.friction for v in player_vel]
        if recovering:
            recovering -= 1
            enemy[0] += enemy_vel[0]
            enemy[1] += enemy_vel[1]
            enemy_vel = [v * p.friction for v in enemy_vel]
        else:
            dx, dy = player[0] - enemy[0], ground - enemy[1]
            distance = math.hypot(dx, dy) or 1.0
            enemy[0] += p.lunge_speed * dx / distance
            enemy[1] += p.lunge_speed * dy / distance  # drift back to the ground line
        clamp_x(player)
        clamp_x(enemy)
        angle += p.spin
        player_poly = regular_polygon(5, p.radius, tuple(player), rotation=-math.pi / 2)
        enemy_poly = regular_polygon(5, p.radius, tuple(enemy), rotation=angle)

        # 3. broad phase: padded AABB opens the window on its rising edge
        (px0, py0), (px1, py1) = points_bounds(player_poly)
        padded = ((px0 - p.pad, py0 - p.pad), (px1 + p.pad, py1 + p.pad))
        e_min, e_max = points_bounds(enemy_poly)
        padded_overlap = aabb_overlap(padded[0], padded[1], e_min, e_max)
        if padded_overlap and not was_padded and window == 0:
            window = p.window_frames
            events.append(Event(f, "window"))
        was_padded = padded_overlap

        # 4. input
        if pressed:
            if window > 0:
                armed = True
                events.append(Event(f, "press"))
            else:
                events.append(Event(f, "whiff"))

        # 5. narrow phase
        in_window = window > 0
        contact = sat(player_poly, enemy_poly)
        if contact is not None:
            (ax, ay), depth = contact  # moving the player by axis * depth separates it
            if window > 0 and armed:
                events.append(Event(f, "parry"))
                enemy[0] -= ax * depth
                enemy[1] -= ay * depth
                enemy_vel = [-ax * p.knockback, -ay * p.knockback]
            else:
                events.append(Event(f, "hit"))
                player[0] += ax * depth
                player[1] += ay * depth
                player_vel = [ax * p.knockback, ay * p.knockback]
                enemy_vel = [-ax * p.knockback / 2, -ay * p.knockback / 2]
            recovering = p.recover_frames
            window = 0
            armed = False
        elif window > 0:
            window -= 1
            if window == 0:
                events.append(Event(f, "expired"))
                armed = False
        out.append(FrameState(f, player_poly, enemy_poly, padded, in_window, window, armed, contact, events))
    return out


def events_of(states: list[FrameState]) -> list[Event]:
    """All events in frame order."""
    return [e for s in states for e in s.events]
