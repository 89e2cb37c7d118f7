; add_bcd: a + b with CLC but no CLD: right only when the caller enters in binary mode (D = 0).
        .org $c000
add_bcd:
        clc
        adc b_val
        sta sum
        rts
b_val:  .byte 0
sum:    .byte 0
