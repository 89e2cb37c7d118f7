; sumto (ACME syntax): A = 1 + 2 + ... + X (X = 0..4); the same bytes as sumto.s
        * = $c000
sumto   lda #0
        cpx #0
        beq done
loop    clc
        adc table-1,x
        bcs over            ; never taken for X <= 4
        dex
        bne loop
done    rts
over    lda #$ff
        rts
        !fill $c0fe - *
table   !byte 1, 2, 3, 4
