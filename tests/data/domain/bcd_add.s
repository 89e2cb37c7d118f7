; bcd_add: sum = a + b in packed BCD (four digits each, low byte first); carry set when the sum
; passes 9999. Only BCD inputs (every nibble 0..9) are its domain.
        .org $c000
bcd_add:
        sed
        clc
        lda a_val
        adc b_val
        sta sum
        lda a_val+1
        adc b_val+1
        sta sum+1
        cld
        rts
a_val:  .byte 0, 0
b_val:  .byte 0, 0
sum:    .byte 0, 0
