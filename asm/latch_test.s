; latch_test: did two given sprites collide (with anything) since $D01E was last read?
; The study's "hardware latch" method: what a program pays per frame to ask the VIC-II.
; In:  zero page `latch_bits` = the two sprites' bits, e.g. %00000011 for sprites 0 and 1.
; Out: C = 1 when both bits were set in $D01E, else C = 0.  A = the bits of the pair that were set.
; Side effect: the read clears $D01E for every sprite (a copy is kept in `latch_copy` for the
; other pairs of the same frame: test them with latch_again, which does not touch the chip).
; Cost (JSR excluded): latch_test 4+3+3+3+6 = 19 cycles, latch_again 3+3+3+6 = 15 cycles, every call.
; $D01E: sprite-sprite collision register, clear-on-read [Bauer 3.8.2; C64 PRG p.145].
.alias sprite_sprite $d01e
.alias latch_bits $fb
.alias latch_copy $fc
.org $c000
latch_test:
        lda sprite_sprite       ; read and clear the latch
        sta latch_copy
        and latch_bits
        cmp latch_bits          ; C = 1 exactly when both bits are set (A is a subset of the bits)
        rts
latch_again:
        lda latch_copy
        and latch_bits
        cmp latch_bits
        rts
