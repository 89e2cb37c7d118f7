.label y1 = $11
.label x2 = $13
.label y2 = $14
.label r2 = $15
.label t = $16
.label sq_lo = $C100
.label sq_hi = $C200
.label circle_rsq1_lo = $C300
.label circle_rsq1_hi = $C400
.label circle_dxneg_lo = $C500
.label circle_dxneg_hi = $C600
.label circle_dyn_lo = $C700
.label circle_dyn_hi = $C800
        * = $C000
circle:
        sec
        sbc x2
        tay
        txa
        bcc _xneg
        adc r2
        tax
        lda circle_rsq1_lo,x
        sbc sq_lo,y
        sta t
        lda circle_rsq1_hi,x
        sbc sq_hi,y
        bcs _dy
        rts
_xneg:
        adc r2
        tax
        lda sq_lo,x
        sbc circle_dxneg_lo,y
        sta t
        lda sq_hi,x
        sbc circle_dxneg_hi,y
        bcc _miss
_dy:
        tax
        lda y1
        sbc y2
        tay
        bcc _yneg
        lda t
        sbc sq_lo,y
        txa
        sbc sq_hi,y
        rts
_yneg:
        lda t
        sbc circle_dyn_lo,y
        txa
        sbc circle_dyn_hi,y
_miss:
        rts
