; wide: A = the high byte of a 16-bit input given in A (low) and X (high), plus 1; Y = its low byte.
; A fixture with a register input wider than a byte (the compiled engine shifts it into X).
        .org $c000
wide:
        tay
        txa
        clc
        adc #1
        rts
