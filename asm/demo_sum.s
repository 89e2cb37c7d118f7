; demo_sum: add the bytes of a table (the demo's first routine).
; In:  X = number of bytes (1-255), table at `values`.   Out: A = low byte of the sum, Y = high byte.
; Cost (JSR excluded): 11 + 12*X cycles, plus 3 for each add that carries (BCC not taken, INY, CLC),
; while `values` does not cross a page. See `retro run asm/demo_sum.s --entry demo_sum --x 8 --trace`.
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
