; aabb8: do two boxes overlap? 8-bit coordinates and sizes.
;
; In:  registers A = ax, X = ay (box A's position, as a caller that just loaded or moved it
;      holds it); zero page $10 aw  $11 ah (box A's size), $12 bx  $13 by  $14 bw  $15 bh (box B).
;      Box A: pixels ax..ax+aw-1, ay..ay+ah-1; box B likewise. The carry on entry is ignored.
; Out: carry set = the boxes share at least one pixel; carry clear = they do not.
;      A, flags other than C: undefined. X, Y and the zero-page inputs are preserved (Y is not
;      used: it stays free for the caller's object index).
; Edge convention (the same as retro.geometry): half-open boxes; boxes that touch along an edge
;      (ax + aw == bx) do NOT overlap.
; Method: x: one CMP decides which box starts first, then the distance between the starts is
;      compared with the width of that box (ax < bx: ~dx + aw carries iff aw > dx; ax >= bx:
;      ex = ax - bx against bw). The x test leaves a known carry (set after the first case, clear
;      after the second), so y needs no CLC/SEC to start: each entry carry has its own copy of the
;      y test, whose SBC gives both the sign of ay - by and the distance, and each sign case turns
;      that into ~distance with the carry clear before the final ADC of the size ("size > distance").
;      The distance is always a difference, never x + w, so boxes reaching past 255 are plain
;      integers (no wrap).
; Domain: every 8-bit input with w >= 1 and h >= 1 (`retro check aabb8` reports the exact domain).
; Cost: 20-34 cycles (static 20-34), no tables; see `retro cycles aabb8` and docs/routines.md for
;      what bounds the worst case (a hit where box B starts first on y).
        .org $c000
        .alias aw $10
        .alias ah $11
        .alias bx $12
        .alias by $13
        .alias bw $14
        .alias bh $15

aabb8:
        cmp bx                  ; C = ax >= bx
        bcs _b_left
        sbc bx                  ; C=0: A = ax - bx - 1 = ~dx, dx = bx - ax >= 1
        adc aw                  ; C = (aw > dx)
        bcc _out                ; no overlap on x (C clear)
        txa                     ; C=1 from here
        sbc by                  ; A = ay - by, C = ay >= by
        bcc _c1_a_above
        eor #$ff                ; ay >= by: ~ey, ey = ay - by
        clc
        adc bh                  ; C = (bh > ey)
        rts
_c1_a_above:                    ; ay < by: A = 256 - dy, dy = by - ay >= 1, C=0
        sbc #0                  ; A = ~dy (A >= 1, so C=1)
        clc
        adc ah                  ; C = (ah > dy)
_out:   rts
_b_left:
        sbc bx                  ; C=1: A = ex = ax - bx
        cmp bw                  ; C = (ex >= bw): no overlap on x
        bcs _miss
        txa                     ; C=0 from here
        sbc by                  ; A = ay - by - 1, C = ay > by
        bcc _c0_a_above
        adc #0                  ; ay > by: A = ey - 1 + 1 = ey, C=0 (ey - 1 <= 254)
        eor #$ff                ; ~ey
        adc bh                  ; C = (bh > ey)
        rts
_c0_a_above:                    ; ay <= by: A = ~dy, C=0
        adc ah                  ; C = (ah > dy)
        rts
_miss:  clc
        rts
