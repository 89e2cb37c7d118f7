; aabb8: do two boxes overlap? 8-bit coordinates and sizes.
;
; In (zero page):  $10 ax  $11 ay  $12 aw  $13 ah      box A: pixels ax..ax+aw-1, ay..ay+ah-1
;                  $14 bx  $15 by  $16 bw  $17 bh      box B
; Out: carry set = the boxes share at least one pixel; carry clear = they do not.
;      A, flags other than C: undefined. X, Y and the inputs are preserved.
; Edge convention (the same as retro.geometry): half-open boxes; boxes that touch along an edge
;      (ax + aw == bx) do NOT overlap.
; Method: per axis, split on which box starts first (one CMP), then compare the distance between
;      the starts with the width of the box that starts first. The distance is formed as a
;      difference, never as x + w, so boxes reaching past 255 are handled as plain integers.
; Domain: every 8-bit input with w >= 1 and h >= 1 (`retro check aabb8` reports the exact domain).
; Cost: see `retro cycles aabb8` (docs/routines.md): 6 zero-page reads, no tables.
        .org $c000
        .alias ax $10
        .alias ay $11
        .alias aw $12
        .alias ah $13
        .alias bx $14
        .alias by $15
        .alias bw $16
        .alias bh $17

aabb8:
        lda ax
        cmp bx
        bcs _b_first            ; ax >= bx
        sbc bx                  ; C=0: A = ax - bx - 1 = ~dx, dx = bx - ax >= 1
        adc aw                  ; C = (~dx + aw >= 256) = (aw > dx)
        bcc _done               ; no overlap on x (C clear)
        clc
_y:     lda ay                  ; C=0 on entry
        sbc by                  ; A = ay - by - 1, C = (ay > by)
        bcc _a_above            ; ay <= by: A = ~dy, dy = by - ay
        adc #0                  ; C=1: A = ey - 1 -> ey = ay - by, C=0
        eor #$ff                ; ~ey
        adc bh                  ; C = (bh > ey)
        rts
_a_above:
        adc ah                  ; C = (ah > dy)
_done:  rts
_b_first:
        sbc bx                  ; C=1: A = ex = ax - bx
        cmp bw                  ; C = (ex >= bw): no overlap on x
        bcc _y
        clc
        rts
