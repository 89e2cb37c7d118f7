b_val equ $C00C
temp equ $C00D
        processor 6502
        org $C000
wasteful
        stx temp
        lda temp
        clc
        clc
        adc b_val
        rts
