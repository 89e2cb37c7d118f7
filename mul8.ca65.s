sum_lo = $10
sum_hi = $13
dif_lo = $15
dif_hi = $17
        .org $C000
mul8:
        sta sum_lo
        sta sum_hi
        eor #$FF
        sta dif_lo
        sta dif_hi
        sec
        lda (sum_lo),y
        sbc (dif_lo),y
        tax
        lda (sum_hi),y
        sbc (dif_hi),y
        rts
