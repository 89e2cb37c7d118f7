aw = $10
ah = $11
bx = $12
by = $13
bw = $14
bh = $15
        * = $C000
aabb8
        cmp bx
        bcs _b_left
        sbc bx
        adc aw
        bcc _out
        txa
        sbc by
        bcc _c1_a_above
        eor #$FF
        clc
        adc bh
        rts
_c1_a_above
        sbc #$00
        clc
        adc ah
_out
        rts
_b_left
        sbc bx
        cmp bw
        bcs _miss
        txa
        sbc by
        bcc _c0_a_above
        adc #$00
        eor #$FF
        adc bh
        rts
_c0_a_above
        adc ah
        rts
_miss
        clc
        rts
