; absdiff: A = |A - m|. The textbook way: subtract, and negate (two's complement) when it borrowed.
        .org $c000
absdiff:
        sec
        sbc m
        bcs done
        eor #$ff
        adc #1
done:   rts
m:      .byte 0
