// Written by hand in Kick Assembler syntax (Kick Assembler is not packaged by Debian, so this was
// not assembled here): the same bytes at the same addresses as acme_boxhit.asm.
// boxhit: carry set when box A (zero page) and box B (absolute) overlap; touching is no overlap.
.label boxa_x = $fb
.label boxa_y = $fc
.label boxa_w = $fd
.label boxa_h = $fe

* = $c000 "boxhit"
boxhit:
        lda boxb_x
        clc
        adc boxb_w
        cmp boxa_x
        beq miss
        bcc miss
        lda boxa_x
        clc
        adc boxa_w
        cmp boxb_x
        beq miss
        bcc miss
        lda boxb_y
        clc
        adc boxb_h
        cmp boxa_y
        beq miss
        bcc miss
        lda boxa_y
        clc
        adc boxa_h
        cmp boxb_y
        beq miss
        bcc miss
        sec
        rts
miss:
        clc
        rts

fill:
.namespace fill {
        ldx #3
loop:
        sta buf,x
        dex
        bpl loop
        rts
}

sum:
.namespace sum {
        lda #0
        ldx #3
loop:
        clc
        adc buf,x
        dex
        bpl loop
        rts
}

boxb_x: .byte 0
boxb_y: .byte 0
boxb_w: .byte 0
boxb_h: .byte 0
buf:    .byte 0, 0, 0, 0
