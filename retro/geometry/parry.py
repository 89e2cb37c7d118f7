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
    inputs = _inputs_by_frame(script, frames, source)
    world = _World(params)
    out: list[FrameState] = []
    for f in range(frames):
        events: list[Event] = []
        pressed = False
        for action in inputs.get(f, ()):
            if action == "parry":
                pressed = True
            else:
                world.walk = {"left": -1, "right": 1, "stop": 0}[action]
        player_poly, enemy_poly = world.move()  # 2. motion
        padded = world.broad_phase(f, player_poly, enemy_poly, events)  # 3. the window opens on its rising edge
        if pressed:  # 4. input
            if world.window > 0:
                world.armed = True
                events.append(Event(f, "press"))
            else:
                events.append(Event(f, "whiff"))
        in_window = world.window > 0
        contact = world.narrow_phase(f, player_poly, enemy_poly, events)  # 5. narrow phase
        out.append(FrameState(f, player_poly, enemy_poly, padded, in_window, world.window, world.armed, contact,
                              events))
    return out


def _inputs_by_frame(script: list[tuple[int, str]], frames: int, source: str) -> dict[int, list[str]]:
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
    return inputs


class _World:
    """The state the loop carries from frame to frame."""

    def __init__(self, p: ParryParams) -> None:
        self.p = p
        self.width, self.height = p.arena
        self.ground = self.height / 2
        self.player = [p.player_start, self.ground]
        self.enemy = [p.enemy_start, self.ground]
        self.player_vel = [0.0, 0.0]
        self.enemy_vel = [0.0, 0.0]
        self.angle = 0.0
        self.walk = 0
        self.window = 0
        self.armed = False
        self.recovering = 0
        self.was_padded = False

    def _clamp(self, pos: list[float]) -> None:
        pos[0] = min(max(pos[0], self.p.radius), self.width - self.p.radius)
        pos[1] = min(max(pos[1], self.p.radius), self.height - self.p.radius)

    def move(self) -> tuple[list, list]:
        """The player walks (and slides), the enemy lunges at it (or slides while it recovers)."""
        p, player, enemy = self.p, self.player, self.enemy
        player[0] += self.walk * p.walk_speed + self.player_vel[0]
        player[1] += self.player_vel[1]
        self.player_vel = [v * p.friction for v in self.player_vel]
        if self.recovering:
            self.recovering -= 1
            enemy[0] += self.enemy_vel[0]
            enemy[1] += self.enemy_vel[1]
            self.enemy_vel = [v * p.friction for v in self.enemy_vel]
        else:
            dx, dy = player[0] - enemy[0], self.ground - enemy[1]
            distance = math.hypot(dx, dy) or 1.0
            enemy[0] += p.lunge_speed * dx / distance
            enemy[1] += p.lunge_speed * dy / distance  # drift back to the ground line
        self._clamp(player)
        self._clamp(enemy)
        self.angle += p.spin
        return (regular_polygon(5, p.radius, tuple(player), rotation=-math.pi / 2),
                regular_polygon(5, p.radius, tuple(enemy), rotation=self.angle))

    def broad_phase(self, f: int, player_poly: list, enemy_poly: list, events: list[Event]) -> tuple:
        """The padded AABB of the player against the enemy's box: its rising edge opens the window."""
        pad = self.p.pad
        (px0, py0), (px1, py1) = points_bounds(player_poly)
        padded = ((px0 - pad, py0 - pad), (px1 + pad, py1 + pad))
        e_min, e_max = points_bounds(enemy_poly)
        padded_overlap = aabb_overlap(padded[0], padded[1], e_min, e_max)
        if padded_overlap and not self.was_padded and self.window == 0:
            self.window = self.p.window_frames
            events.append(Event(f, "window"))
        self.was_padded = padded_overlap
        return padded

    def narrow_phase(self, f: int, player_poly: list, enemy_poly: list, events: list[Event]):
        """SAT contact: a parry (armed in the window) knocks the enemy back, else a hit the player."""
        p = self.p
        contact = sat(player_poly, enemy_poly)
        if contact is not None:
            (ax, ay), depth = contact  # moving the player by axis * depth separates it
            if self.window > 0 and self.armed:
                events.append(Event(f, "parry"))
                self.enemy[0] -= ax * depth
                self.enemy[1] -= ay * depth
                self.enemy_vel = [-ax * p.knockback, -ay * p.knockback]
            else:
                events.append(Event(f, "hit"))
                self.player[0] += ax * depth
                self.player[1] += ay * depth
                self.player_vel = [ax * p.knockback, ay * p.knockback]
                self.enemy_vel = [-ax * p.knockback / 2, -ay * p.knockback / 2]
            self.recovering = p.recover_frames
            self.window = 0
            self.armed = False
        elif self.window > 0:
            self.window -= 1
            if self.window == 0:
                events.append(Event(f, "expired"))
                self.armed = False
        return contact


def events_of(states: list[FrameState]) -> list[Event]:
    """All events in frame order."""
    return [e for s in states for e in s.events]
