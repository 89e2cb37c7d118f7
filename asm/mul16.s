; mul16: unsigned 16 x 16 -> 32-bit multiply by shift and add.
;
; In (zero page): $10-$11 = a, $12-$13 = b (little-endian words).
; Out: $14-$17 = a * b (little-endian, 32 bits). A = the product's high byte, X = 0, Y: undefined,
;      C: undefined. a and b are preserved.
; Method: the 32-bit product register p3:p2:p1:p0 starts as 0:0:b; each of 16 steps shifts the
;      multiplier's next bit out at the bottom (into C), adds a to the high half p3:p2 when that bit
;      is 1 (the carry of the 17-bit sum becomes the top bit of the next shift), then shifts the
;      whole register right by one: the product's bits fill p1:p0 from the top as b's bits leave it.
;      p3 lives in A during the loop (ROR A is 3 cycles cheaper than ROR zp), Y holds it across
;      the add of the low byte.
; Loop bounds (for the static analysis): _step runs 16 times.
; Cost: 437 + 17 * (one bits of b) cycles: 437-709, mean 573 over all 2^32 inputs (each bit of b
;      is 1 in half of them); a does not matter. No tables, no page crossings (the branches stay
;      within the page).
; Domain: all 2^32 inputs.
        .org $c000
        .alias ma $10           ; a (multiplicand), 2 bytes
        .alias mb $12           ; b (multiplier), 2 bytes
        .alias p0 $14           ; the product, 4 bytes
        .alias p1 $15
        .alias p2 $16
        .alias p3 $17

mul16:
        lda mb
        sta p0
        lda mb+1
        sta p1
        lda #0                  ; A = p3 = 0
        sta p2
        ldx #16
        lsr p1                  ; C = b's bit 0
        ror p0
_step:
        bcc _shift
        tay                     ; p3:p2 += a
        clc
        lda p2
        adc ma
        sta p2
        tya
        adc ma+1
_shift:
        ror                     ; C:p3:p2:p1:p0 >> 1, the next bit of b into C
        ror p2
        ror p1
        ror p0
        dex
        bne _step
        sta p3
        rts
