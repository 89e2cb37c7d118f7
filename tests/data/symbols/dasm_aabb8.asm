; asm/aabb8.s (the project's 8-bit box test) in DASM syntax, as an Atari 2600 or VIC-20 project
; would write it: `.` locals in a SUBROUTINE, equates for the zero-page inputs, an EQM macro and
; a negative constant beside them. Same bytes as `retro asm asm/aabb8.s`.
        processor 6502
aw      equ $10
ah      equ $11
bx      equ $12
by      equ $13
bw      equ $14
bh      equ $15
INPUTS  eqm aw,ah,bx,by,bw,bh     ; a string macro: skipped
NO_HIT  equ -1                    ; a negative constant: skipped

        org $c000
aabb8   SUBROUTINE
        cmp bx                  ; C = ax >= bx
        bcs .b_left
        sbc bx                  ; C=0: A = ~dx
        adc aw                  ; C = (aw > dx)
        bcc .out
        txa
        sbc by                  ; A = ay - by, C = ay >= by
        bcc .c1_a_above
        eor #$ff
        clc
        adc bh                  ; C = (bh > ey)
        rts
.c1_a_above
        sbc #0
        clc
        adc ah                  ; C = (ah > dy)
.out    rts
.b_left
        sbc bx                  ; C=1: A = ex = ax - bx
        cmp bw
        bcs .miss
        txa
        sbc by
        bcc .c0_a_above
        adc #0
        eor #$ff
        adc bh
        rts
.c0_a_above
        adc ah
        rts
.miss   clc
        rts
