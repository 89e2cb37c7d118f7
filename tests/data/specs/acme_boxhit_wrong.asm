; boxhit (DELIBERATELY WRONG: counts boxes touching on x as a hit): carry set when box A (zero page) and box B (absolute) overlap; touching is no overlap.
; Box A: boxa_x, boxa_y, boxa_w, boxa_h; box B: boxb_x, boxb_y, boxb_w, boxb_h (x + w <= 255).
; fill: buf[0..3] = A.  sum: A = buf[0] + buf[1] + buf[2] + buf[3] (mod 256).
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

!zone fill
fill
        ldx #3
.loop
        sta buf,x
        dex
        bpl .loop
        rts

!zone sum
sum
        lda #0
        ldx #3
.loop
        clc
        adc buf,x
        dex
        bpl .loop
        rts

boxb_x  !byte 0
boxb_y  !byte 0
boxb_w  !byte 0
boxb_h  !byte 0
buf     !byte 0, 0, 0, 0
