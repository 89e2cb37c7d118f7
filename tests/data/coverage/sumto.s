; sumto: A = 1 + 2 + ... + X (X = 0..4), the hand-worked routine of the coverage tests (docs/coverage.md)
; The table lies across a page boundary, so ADC table-1,X takes 5 cycles for X >= 3 and 4 below.
        .org $c000
sumto:  lda #0
        cpx #0
        beq done
loop:   clc
        adc table-1,x
        bcs over            ; never taken for X <= 4 (the sum stays below 256)
        dex
        bne loop
done:   rts
over:   lda #$ff
        rts
        .res $c0fe - *
table:  .byte 1, 2, 3, 4
