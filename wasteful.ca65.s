b_val = $C00C
temp = $C00D
        .org $C000
wasteful:
        stx temp
        lda temp
        clc
        clc
        adc b_val
        rts
