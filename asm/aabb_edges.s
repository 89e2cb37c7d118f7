; aabb_edges: do two boxes overlap, from edges computed once per object per frame (the convention
; games use: each object's edges are prepared once, then many pairs are tested).
;
; In:  registers A = box A's left, X = box A's top, Y = box A's right - 1 (its last column);
;      zero page $10 a_bottom1 (box A's last row), $11 b_left, $12 b_right (box B's first column
;      past it: left + width), $13 b_top, $14 b_bottom (top + height).
;      `aabb_edges_prepare` makes all six edges of an object from x, y, w, h.
; Out: carry set = the boxes share at least one pixel; clear = they do not. A: undefined;
;      X, Y and the zero page preserved.
; Edge convention (as retro.geometry): half-open boxes; boxes that touch do NOT overlap.
; Method: four comparisons, each a CMP/CPX/CPY with the carry answering one separating test:
;      a_left >= b_right (miss), a_right1 < b_left (miss), a_top >= b_bottom (miss), and the last,
;      a_bottom1 >= b_top, leaves the answer in the carry for the RTS.
; Domain: the edges of boxes with w, h >= 1 and x + w <= 255, y + h <= 255 (right and bottom fit
;      in a byte); `retro check aabb_edges` states it exactly.
; Cost: 14-27 cycles (static 14-27; 27 on a hit). aabb_edges_prepare: 44 cycles.
        .org $c000
        .alias a_bottom1 $10
        .alias b_left    $11
        .alias b_right   $12
        .alias b_top     $13
        .alias b_bottom  $14

aabb_edges:
        cmp b_right             ; C = a_left >= b_right: A starts past B's end
        bcs _miss
        cpy b_left              ; C = a_right1 >= b_left
        bcc _out                ; A ends before B starts (C clear: no overlap)
        cpx b_bottom            ; C = a_top >= b_bottom
        bcs _miss
        lda a_bottom1
        cmp b_top               ; C = a_bottom1 >= b_top: the answer
_out:   rts
_miss:  clc
        rts

; aabb_edges_prepare: an object's six edges from its box.
; In:  zero page $18 px, $19 py, $1a pw, $1b ph (w, h >= 1; x + w <= 255, y + h <= 255).
; Out: zero page $1c left, $1d top, $1e right1 (x + w - 1), $1f right (x + w), $20 bottom1, $21 bottom.
        .alias px $18
        .alias py $19
        .alias pw $1a
        .alias ph $1b
        .alias e_left $1c
        .alias e_top $1d
        .alias e_right1 $1e
        .alias e_right $1f
        .alias e_bottom1 $20
        .alias e_bottom $21

aabb_edges_prepare:
        lda px
        sta e_left
        clc
        adc pw
        sta e_right
        sbc #0                  ; C clear (no carry out in the domain): A = right - 1
        sta e_right1
        lda py
        sta e_top
        clc
        adc ph
        sta e_bottom
        sbc #0
        sta e_bottom1
        rts
