; scratch: a + the byte at $fb, a zero-page byte nothing declares (power-on RAM is 0, a caller's is not).
        .org $c000
scratch:
        clc
        lda a_val
        adc $fb
        sta sum
        rts
a_val:  .byte 0
sum:    .byte 0
