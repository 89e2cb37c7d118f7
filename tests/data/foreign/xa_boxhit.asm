; boxhit sets the carry when box A (zero page) and box B (absolute) overlap, touching is no overlap.
; Box A at boxa_x, boxa_y, boxa_w, boxa_h, box B at boxb_x, boxb_y, boxb_w, boxb_h (x + w <= 255).
; fill stores A into buf[0..3], sum returns in A the sum of buf[0..3] (mod 256).
boxa_x = $fb
boxa_y = $fc
boxa_w = $fd
boxa_h = $fe

        * = $c000
boxhit
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
miss
        clc
        rts

fill    .(
        ldx #3
loop
        sta buf,x
        dex
        bpl loop
        rts
        .)

sum     .(
        lda #0
        ldx #3
loop
        clc
        adc buf,x
        dex
        bpl loop
        rts
        .)

boxb_x  .byt 0
boxb_y  .byt 0
boxb_w  .byt 0
boxb_h  .byt 0
buf     .byt 0, 0, 0, 0
