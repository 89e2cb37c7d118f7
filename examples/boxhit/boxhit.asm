; boxhit: do two boxes overlap? (ACME syntax; the example of "Check your own routine" in README.md)
;
; In:  box A in zero page: boxa_x, boxa_y, boxa_w, boxa_h; box B in the program: boxb_x ... boxb_h.
;      Each box covers x .. x+w-1 and y .. y+h-1.
; Out: carry set = the boxes share a pixel; clear = they do not (touching boxes do not).
; Domain: w, h >= 1 and x + w <= 255, y + h <= 255 (the sums are 8-bit).
; Build: acme --format cbm --outfile boxhit.prg --symbollist boxhit.sym boxhit.asm
boxa_x = $fb
boxa_y = $fc
boxa_w = $fd
boxa_h = $fe

        * = $c000
boxhit
        lda boxb_x              ; B.x + B.w > A.x ?
        clc
        adc boxb_w
        cmp boxa_x
        beq miss
        bcc miss
        lda boxa_x              ; A.x + A.w > B.x ?
        clc
        adc boxa_w
        cmp boxb_x
        beq miss
        bcc miss
        lda boxb_y              ; the same on y
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

boxb_x  !byte 0
boxb_y  !byte 0
boxb_w  !byte 0
boxb_h  !byte 0
