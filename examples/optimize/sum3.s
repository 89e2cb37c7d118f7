; sum3: A = X + b + c, written with waste (a store and load where TXA does, a carry cleared twice).
; Three byte inputs: 2^24 cases, past what a proof sweeps, so z3 proves the changes (docs/optimize.md).
        .org $c000
sum3:
        stx temp
        lda temp
        clc
        clc
        adc b_val
        clc
        adc c_val
        rts
b_val:  .byte 0
c_val:  .byte 0
temp:   .byte 0
