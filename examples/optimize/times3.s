; times3: A = 3 * A (the low byte), the textbook way: 2A by a shift, plus A kept in zero page
; (as in MADS's "Multiplication by 3" tip, 8 bits of it). A 256-byte table of the answers sits
; at times3_table; `retro optimize --tables times3` lets a candidate read it (docs/optimize.md).
        .org $c000
.alias t $fb
times3:
        sta t
        asl
        clc
        adc t
        rts
        .advance $c100
times3_table:
