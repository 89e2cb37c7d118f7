; overlap8: do two 8-pixel spans at a and b miss each other? C = |a - b| >= 8. The textbook way:
; the absolute difference, then a compare.
        .org $c000
overlap8:
        sec
        sbc b_pos
        bcs compare
        eor #$ff
        adc #1
compare:
        cmp #8
        rts
b_pos:  .byte 0
