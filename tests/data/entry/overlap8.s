; overlap8: do two 8-pixel spans overlap? |a - b| < 8 -> carry set.
; The superoptimiser's routine of issue 23: it never clears the carry before SBC, so it is right
; only when the caller enters with C = 0 (and D = 0): with the carry set it answers a = 207,
; b = 215 (8 apart) as a hit.
        .org $c000
overlap8:
        sbc b_pos
        bcc compare
        adc #$f8
compare:
        cmp #$f8
        rts
b_pos:  .byte 0
