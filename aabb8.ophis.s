.alias aw $10
.alias ah $11
.alias bx $12
.alias by $13
.alias bw $14
.alias bh $15
        .org $C000
aabb8:
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
_c1_a_above:
        sbc #$00
        clc
        adc ah
_out:
        rts
_b_left:
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
_c0_a_above:
        adc ah
        rts
_miss:
        clc
        rts
