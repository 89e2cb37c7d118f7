.export my_routine
.segment "CODE"
my_routine:
        clc
        adc #5
        sta result
        lda #0
        adc #0
        sta result+1
        rts
result: .byte 0, 0
