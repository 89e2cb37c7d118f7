; index_x: the byte of a table at index i, read through X, which the routine expects to be 0
; (it adds i to X with INX in a loop instead of loading it).
        .org $c000
index_x:
        ldy count
        beq done
step:   inx
        dey
        bne step
done:   lda table,x
        sta value
        rts
count:  .byte 0
value:  .byte 0
table:  .byte 3, 1, 4, 1, 5, 9, 2, 6, 5, 3, 5, 8, 9, 7, 9, 3
