; aabb8_txa: a deliberately wasteful version of asm/aabb8.s with loads where transfers would do: ay is stored on entry and loaded back
; instead of TXA (twice).
;
; The optimiser must reach asm/aabb8.s's cost (tests/optimize/test_wasteful.py).
        .org $c000
        .alias aw $10
        .alias ah $11
        .alias bx $12
        .alias by $13
        .alias bw $14
        .alias bh $15
        .alias ay_copy $16

aabb8_txa:
        stx ay_copy             ; waste: X stays ay throughout
        cmp bx                  ; C = ax >= bx
        bcs _b_left
        sbc bx                  ; C=0: A = ax - bx - 1 = ~dx, dx = bx - ax >= 1
        adc aw                  ; C = (aw > dx)
        bcc _out                ; no overlap on x (C clear)
        lda ay_copy             ; waste: TXA does it
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
        lda ay_copy             ; waste: TXA does it
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
