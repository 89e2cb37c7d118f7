; boxhit: carry set when box A (zero page) and box B (absolute) overlap; touching is no overlap.
; Box A: boxa_x, boxa_y, boxa_w, boxa_h; box B: boxb_x, boxb_y, boxb_w, boxb_h (x + w <= 255).
; fill: buf[0..3] = A.  sum: A = buf[0] + buf[1] + buf[2] + buf[3] (mod 256).
        processor 6502
; every kind of line DASM's -s writes, around the boxhit routine (its bytes unchanged at $C000)
PLAYER_Y eqm $0160               ; EQM string macros: `0000 str eqm ( S) "$0160"`
HUD_TEXT eqm "score"
TITLE   equ "hi"                  ; a string constant: its bytes as the value, then the string
DELTA   equ -128                  ; a negative constant: ffffffffffffff80
WIDE    equ $12345                ; wider than 16 bits
COUNT   set 3                     ; SET, set again below
COUNT   set COUNT+1
        IFCONST PAL               ; never defined: an unresolved name, `0000 ???? (R )`
        ENDIF
        IFNCONST NO_ILLEGAL_OPCODES ; as in the common macro.h
        ENDIF
boxa_x = $fb
boxa_y = $fc
boxa_w = $fd
boxa_h = $fe

        org $c000
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

fill    SUBROUTINE
        ldx #3
.loop
        sta buf,x
        dex
        bpl .loop
        rts

sum     SUBROUTINE
        lda #0
        ldx #3
.loop
        clc
        adc buf,x
        dex
        bpl .loop
        rts

boxb_x  .byte 0
boxb_y  .byte 0
boxb_w  .byte 0
boxb_h  .byte 0
buf     .byte 0, 0, 0, 0

; a third SUBROUTINE with a local (3.done) and a `$` local (10$1$: DASM numbers `$` blocks apart)
wait    SUBROUTINE
        ldx #COUNT
1$      dex
        bne 1$
.done   rts
