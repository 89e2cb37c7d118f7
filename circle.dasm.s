y1 equ $11
x2 equ $13
y2 equ $14
r2 equ $15
t equ $16
sq_lo equ $C100
sq_hi equ $C200
circle_rsq1_lo equ $C300
circle_rsq1_hi equ $C400
circle_dxneg_lo equ $C500
circle_dxneg_hi equ $C600
circle_dyn_lo equ $C700
circle_dyn_hi equ $C800
        processor 6502
        org $C000
circle
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
_xneg
        adc r2
        tax
        lda sq_lo,x
        sbc circle_dxneg_lo,y
        sta t
        lda sq_hi,x
        sbc circle_dxneg_hi,y
        bcc _miss
_dy
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
_yneg
        lda t
        sbc circle_dyn_lo,y
        txa
        sbc circle_dyn_hi,y
_miss
        rts
