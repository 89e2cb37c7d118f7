.label sum_lo = $10
.label sum_hi = $13
.label dif_lo = $15
.label dif_hi = $17
        * = $C000
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
