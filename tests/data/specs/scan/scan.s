; scan: X = index of the first of 8 enemy X positions equal to A ($FF when none); total (16-bit)
; = the sum of the 8 positions, plus `bonus` when the carry is set on entry. The sum is made by a
; subroutine (JSR), so the static analysis must include its cost and bound its loop.
        .org $c000
scan:   sta key
        lda #0
        bcc _nobonus
        lda bonus
_nobonus:
        sta total
        lda #0
        sta total+1
        jsr total_up
        ldx #0
_loop:  lda enemy_x,x
        cmp key
        beq _found
        inx
        cpx #8
        bne _loop
        ldx #$ff
_found: rts

total_up:
        ldy #7
_sum:   lda enemy_x,y
        clc
        adc total
        sta total
        bcc _nocarry
        inc total+1
_nocarry:
        dey
        bpl _sum
        rts

key:     .byte 0
total:   .word 0
bonus:   .byte 0
enemy_x: .byte 0, 0, 0, 0, 0, 0, 0, 0
