; wasteful: A = X + b, written with the waste the optimiser removes: a store and load where a
; transfer does (TXA), and the carry cleared twice.
        .org $c000
wasteful:
        stx temp
        lda temp
        clc
        clc
        adc b_val
        rts
b_val:  .byte 0
temp:   .byte 0
