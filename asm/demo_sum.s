; demo_sum: add the bytes of a table (the demo's first routine).
; In:  X = number of bytes (1-255), table at `values`.   Out: A = low byte of the sum, Y = high byte.
; Cost: 10 + 11*X cycles without carries, +5 per carry... see `retro run asm/demo_sum.s --entry demo_sum --trace`.
.org $c000
demo_sum:
        lda #0
        tay
        clc
add:    adc values-1,x
        bcc +
        iny
        clc
*       dex
        bne add
        rts

values: .byte 200, 100, 50, 25, 12, 6, 3, 1
