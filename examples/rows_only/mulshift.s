; mulshift: unsigned 8 x 8 -> 16-bit multiply by shift and add, the textbook loop.
;
; In:  $FB = a, $FC = b.
; Out: A = high byte, $FB = low byte of a * b (a is shifted out of $FB as the product shifts in).
;      X = 0, $FC unchanged.
; Cost (datasheet cycles): LDA # 2, LDX # 2, LSR zp 5; per bit of a: BCC taken 3 for a 0 bit,
;      BCC 2 + CLC 2 + ADC zp 3 for a 1 bit, then ROR A 2, ROR zp 5, DEX 2, BNE taken 3 (not taken,
;      2, the last time); RTS 6. That is 134 + 4 * (the number of 1 bits in a): 134-166 cycles.
        .org $c000
        .alias lo   $fb
        .alias num2 $fc

mulshift:
        lda #0
        ldx #8
        lsr lo          ; C = the lowest bit of a
loop:   bcc skip
        clc
        adc num2
skip:   ror             ; the carry of the add goes into bit 7
        ror lo          ; the product's low bit in, a's next bit out into C
        dex
        bne loop
        rts
