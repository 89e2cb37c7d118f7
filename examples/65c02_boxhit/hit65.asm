; hit65: do two boxes overlap? The 65C02 example of docs/cpu.md (ACME syntax, `!cpu 65c02`).
;
; Code for a 65C02 machine (Commander X16, Foenix F256, enhanced Apple II): it reads box B through a
; zero-page pointer with the 65C02's (zp) mode, which has no index register, and clears its result
; with STZ. On an NMOS 6502 the (zp) opcodes are JAMs.
;
; In:  box A in zero page: box_ax, box_ay, box_aw, box_ah; box B at boxb_x, boxb_y, boxb_w, boxb_h,
;      reached through the pointer bptr that `init` sets.
;      Each box covers x .. x+w-1 and y .. y+h-1.
; Out: hit = 1 when the boxes share a pixel, 0 when not (touching boxes do not).
; Domain: w, h >= 1 and x + w <= 255, y + h <= 255 (the sums are 8-bit).
; Build: acme --format cbm --outfile hit65.prg --symbollist hit65.sym hit65.asm
        !cpu 65c02
box_ax = $10
box_ay = $11
box_aw = $12
box_ah = $13
bptr = $14                      ; -> box B (2 bytes)
hit = $16

        * = $1000
init    lda #<boxb_x
        sta bptr
        lda #>boxb_x
        sta bptr+1
        rts

hit65   stz hit                 ; assume apart
        lda (bptr)              ; B.x + B.w > A.x ?
        ldy #2
        clc
        adc (bptr),y
        cmp box_ax
        bcc done
        beq done
        lda box_ax              ; A.x + A.w > B.x ?
        clc
        adc box_aw
        cmp (bptr)
        bcc done
        beq done
        ldy #1                  ; B.y + B.h > A.y ?
        lda (bptr),y
        ldy #3
        clc
        adc (bptr),y
        cmp box_ay
        bcc done
        beq done
        lda box_ay              ; A.y + A.h > B.y ?
        clc
        adc box_ah
        ldy #1
        cmp (bptr),y
        bcc done
        beq done
        inc hit
done    rts

boxb_x  !byte 0
boxb_y  !byte 0
boxb_w  !byte 0
boxb_h  !byte 0
