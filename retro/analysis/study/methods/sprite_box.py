"""The tight hitbox in C64 sprite coordinates: 9-bit X edges prepared once per sprite and frame
(asm/sprite_edges_prepare folds the hitbox offsets into the sprite's X/$D010 and Y), then
asm/sprite_edges per pair. The same rule as the tight box; the pairs are placed so that their boxes
cross X = 255/256 (sprite a at X = SPRITE_X), where an 8-bit test would be wrong."""

from __future__ import annotations

from dataclasses import dataclass

from retro.analysis.study.corpus import Pair
from retro.analysis.study.fits import tight_box
from retro.analysis.study.methods.base import ORIGIN
from retro.analysis.study.methods.box import BoxMethod

SPRITE_X = 240  # sprite a's X register value: b's X runs from 217 to 263, its hitbox across 256


@dataclass(frozen=True, kw_only=True)
class SpriteEdgesMethod(BoxMethod):
    def case_maker(self, pair: Pair):
        (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = self.boxes(pair)
        dxs, dys = pair.dx.tolist(), pair.dy.tolist()
        a_left, a_right = SPRITE_X + ax0, SPRITE_X + ax1

        def case(i: int) -> tuple:
            b_left, b_right = SPRITE_X + dxs[i] + bx0, SPRITE_X + dxs[i] + bx1
            return dict(a_left=a_left & 0xFF, a_left_hi=a_left >> 8, a_right=a_right & 0xFF,  # asm/sprite_edges.toml
                        a_right_hi=a_right >> 8, a_top=ORIGIN + ay0, a_bottom1=ORIGIN + ay1 - 1,
                        b_left=b_left & 0xFF, b_left_hi=b_left >> 8, b_right=b_right & 0xFF,
                        b_right_hi=b_right >> 8, b_top=ORIGIN + dys[i] + by0, b_bottom=ORIGIN + dys[i] + by1)
        return case


SPRITE_EDGES = SpriteEdgesMethod(
    key="sprite_edges", label="tight hitbox, 9-bit sprite edges", fit=tight_box, colour="#006400", marker="8",
    routine="sprite_edges", prepare="sprite_edges_prepare", machines=("c64",),
    rule="the bounding boxes of the opaque pixels overlap (half-open), in 9-bit sprite X across 255/256, from "
         "edges prepared once per sprite",
    counted="asm/sprite_edges.s per pair, on edges made once per sprite and frame by sprite_edges_prepare "
            "(not counted here)", origin=__name__)
