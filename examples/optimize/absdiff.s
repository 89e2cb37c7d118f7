; absdiff: A = |A - m|. The textbook way: subtract, and negate (two's complement) when it borrowed.
        .org $c000
.alias m $fb                ; the second operand, in zero page
absdiff:
        sec
        sbc m
        bcs done
        eor #$ff
        adc #1
done:   rts

