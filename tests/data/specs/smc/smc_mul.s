; smc_mul: unsigned 8 x 8 -> 16-bit multiply by quarter squares whose factor a is patched into the
; operands of four indexed reads (a test fixture of self-modifying code, written for retro's tests in
; the style of the fast 6502 multiplies: the tables are page-aligned, the stored byte picks the entry).
; In: A = a, Y = b. Out: X = low byte, A = high byte of a * b.
; Cycles, counted from the datasheet: 4 x STA abs (16), EOR # (2), SEC (2), 2 x LDA abs,Y and
; 2 x SBC abs,Y (16), TAX (2), RTS (6) = 44, plus one per read that crosses a page: the sum reads
; cross when a + b >= 256, the difference reads when (255 - a) + b >= 256, i.e. b > a: 44-48.
        .org $c000
; retro-tables: qsq_lo qsq_hi qsqd_lo qsqd_hi

smc_mul:
        sta sum_lo+1
        sta sum_hi+1
        eor #$ff
        sta dif_lo+1
        sta dif_hi+1
        sec
sum_lo: lda qsq_lo,y
dif_lo: sbc qsqd_lo,y
        tax
sum_hi: lda qsq_hi,y
dif_hi: sbc qsqd_hi,y
        rts
