"""Latch pitfalls: what a program that reads $D01E misses or misattributes.

Each scenario drives the VIC-II bus device (retro.chips.vic.device) the way a program would: the
register writes of a sprite multiplexer and the reads of $D01E happen at chosen raster lines, as
host calls at the machine cycles when the 6502 would make them. The device decides what each read
returns (clear-on-read, bits set as the beam draws the overlap). The truth to compare with is the
model's list of overlapping sprite pairs and the raster line of the first overlap pixel of each
band (retro.chips.vic.model.frame_collisions), which the hardware does not expose.
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.analysis.study.corpus import Shape
from retro.analysis.study.latch import sprites_state
from retro.chips.vic.constants import (
    PAL,
    REG_SPRITE_SPRITE,
    REG_SPRITE_X0,
    REG_SPRITE_Y0,
    VIC_BASE,
)
from retro.chips.vic.device import VicDevice
from retro.chips.vic.model import frame_collisions

D01E = VIC_BASE + REG_SPRITE_SPRITE
READ_LINE = 260  # a main loop that polls the latch once per frame, in the lower border


@dataclass(frozen=True)
class Read:
    frame: int
    line: int
    value: int


@dataclass(frozen=True)
class Pitfall:
    scenario: str
    truth: str  # what really overlapped, and where
    reads: tuple[Read, ...]
    conclusion: str  # what a program that trusts the reads concludes
    kind: str  # misattributed / missed / late / false pairs


def _t(frame: int, line: int) -> int:
    return frame * PAL.frame_cycles + line * PAL.cycles_per_line


def _bits(value: int) -> str:
    return f"%{value:08b}"


def _first_line(state) -> int | None:
    first = frame_collisions(state).first_ss
    return None if first is None else first[0]


def multiplexed(player: Shape, enemy: Shape) -> Pitfall:
    """Sprite 1 shows enemy A in the top band and, moved at line 120, enemy B lower down. The
    player touches A. Read once per frame at the bottom, the bits say 'sprite 1', and sprite 1's
    registers now describe B: the program blames B."""
    a_pos, b_pos, player_pos, split = (160, 72), (60, 180), (150, 70), 120
    top = sprites_state([(player, *player_pos), (enemy, *a_pos)])
    device = VicDevice(top, start_cycle=0)
    reads = []
    for frame in range(2):
        device.write(VIC_BASE + REG_SPRITE_X0 + 2, a_pos[0], _t(frame, 0))
        device.write(VIC_BASE + REG_SPRITE_Y0 + 2, a_pos[1], _t(frame, 0))
        device.write(VIC_BASE + REG_SPRITE_X0 + 2, b_pos[0], _t(frame, split))
        device.write(VIC_BASE + REG_SPRITE_Y0 + 2, b_pos[1], _t(frame, split))
        reads.append(Read(frame, READ_LINE, device.read(D01E, _t(frame, READ_LINE))))
    bottom = sprites_state([(player, *player_pos), (enemy, *b_pos)])
    truth = (f"player (sprite 0) overlaps enemy A (sprite 1, top band) from line {_first_line(top)}; "
             f"enemy B (sprite 1 after the move at line {split}) overlaps nothing: "
             f"{'no overlap' if not frame_collisions(bottom).d01e else 'overlap'}")
    return Pitfall("multiplexed sprite, one read per frame", truth, tuple(reads),
                   f"bits {_bits(reads[-1].value)}: 'sprite 1 hit the player'; sprite 1 is now enemy B, "
                   "so the program blames B for A's hit", "misattributed")


def read_twice(player: Shape, enemy: Shape) -> Pitfall:
    """A raster interrupt reads $D01E at line 100 (say, for a sound), the game logic at the bottom:
    the first read clears the latch, the game logic never sees the hit."""
    state = sprites_state([(player, 150, 70), (enemy, 156, 74)])
    device = VicDevice(state, start_cycle=0)
    reads = []
    for frame in range(2):
        reads.append(Read(frame, 100, device.read(D01E, _t(frame, 100))))
        reads.append(Read(frame, READ_LINE, device.read(D01E, _t(frame, READ_LINE))))
    return Pitfall("two readers in one frame", f"sprites 0 and 1 overlap every frame from line {_first_line(state)}",
                   tuple(reads), "the reader at line 100 gets the bits and clears them; the game logic "
                                 f"at line {READ_LINE} reads {_bits(reads[-1].value)}: no hit, ever", "missed")


def read_before_drawn(player: Shape, enemy: Shape) -> Pitfall:
    """The program reads at line 100 but the overlap is drawn lower: a frame's hit is reported in
    the next frame, when the objects have already moved."""
    state = sprites_state([(player, 150, 170), (enemy, 156, 174)])
    device = VicDevice(state, start_cycle=0)
    reads = tuple(Read(frame, 100, device.read(D01E, _t(frame, 100))) for frame in range(3))
    return Pitfall("read above the overlap", f"sprites 0 and 1 overlap every frame from line {_first_line(state)}",
                   reads, f"frame 0 reads {_bits(reads[0].value)}; each later read reports the previous frame's "
                          "hit: one frame late, so a hit in the last frame before the objects part is acted on "
                          "after they parted", "late")


def two_collisions(player: Shape, enemy: Shape) -> Pitfall:
    """Sprites 0+1 and 2+3 collide far apart: the latch has four bits set, and testing any pair's
    two bits says 'hit' for four pairs that never touched."""
    state = sprites_state([(player, 60, 60), (enemy, 66, 64), (player, 200, 180), (enemy, 206, 184)])
    device = VicDevice(state, start_cycle=0)
    value = device.read(D01E, _t(1, 0))
    real = frame_collisions(state).pairs
    bit_pairs = [(i, j) for i in range(4) for j in range(i + 1, 4) if value >> i & 1 and value >> j & 1]
    false = [p for p in bit_pairs if p not in real]
    return Pitfall("two separate collisions", f"overlapping pairs {list(real)}", (Read(1, 0, value),),
                   f"pairs whose two bits are set: {bit_pairs}; {len(false)} of them ({false}) never touched",
                   "false pairs")


def pitfalls(player: Shape, enemy: Shape) -> list[Pitfall]:
    return [multiplexed(player, enemy), read_twice(player, enemy), read_before_drawn(player, enemy),
            two_collisions(player, enemy)]
