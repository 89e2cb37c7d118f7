; add8: sum = a + b (mod 256), with CLC but in whatever decimal mode the caller left (D clear stated).
        .org $c000
add8:
        clc
        adc b_val
        sta sum
        rts
b_val:  .byte 0
sum:    .byte 0
