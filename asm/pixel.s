; pixel: software pixel-perfect test of two 24 x 21 sprite masks (C64 layout: 3 bytes a row,
; bit 7 of the first byte is the leftmost pixel).
;
; In (zero page):  $10 dx  $11 dy (signed bytes): mask B's top-left pixel relative to mask A's.
;      Masks: pixel_mask_a and pixel_mask_b (63 bytes each, page-aligned, filled by the caller).
; Out: carry set = some pixel is set in both masks; carry clear = none. A, X, Y: undefined.
;      Uses $12-$1b; patches the high bytes of two table reads in its own code (the shift).
; Method: when dx < 0 the masks swap roles (and dx, dy change sign), so the second mask is always
;      k = dx / 8 bytes and s = dx % 8 bits to the right. Only the rows both masks cover are
;      visited; each byte of the second mask is shifted with tables (pixel_shr page s: b >> s,
;      pixel_shl page s: b << (8 - s)), ORed with the spill of its left neighbour, ANDed with the
;      first mask's byte; the first non-zero AND ends the test (early exit on the first hit).
; Loop bounds (for the static analysis): _row runs at most 21 times, _byte at most 3 per row.
; Domain: every dx, dy; |dx| >= 24 or |dy| >= 21 return "no overlap" at once.
        .org $8000              ; below $A000: the tables and masks end at $92FF, clear of the I/O area at $D000
        .alias pdx   $10
        .alias pdy   $11
        .alias pa    $12        ; first mask, row of the first overlapping row, plus k bytes
        .alias pb    $14        ; second mask, its first overlapping row
        .alias sdy   $16
        .alias k     $17
        .alias nb    $18        ; 3 - k: bytes of the second mask that land inside the first
        .alias rows  $19
        .alias prev  $1a
        .alias endm  $1b
; retro-tables: pixel_shr pixel_shl pixel_mask_a pixel_mask_b

pixel:
        lda #>pixel_mask_a
        sta pa+1
        lda #>pixel_mask_b
        sta pb+1
        lda pdy
        sta sdy
        lda pdx
        bpl _oriented
        lda #>pixel_mask_b      ; B starts left of A: swap the roles
        sta pa+1
        lda #>pixel_mask_a
        sta pb+1
        lda #0
        sec
        sbc pdy
        sta sdy
        lda #0
        sec
        sbc pdx                 ; |dx| (dx = -128 gives 128: off to the right, no overlap)
_oriented:
        cmp #24
        bcc _near
        clc                     ; |dx| >= 24: no column in common
        rts
_near:  tax
        and #7
        sta _shr+2              ; self-modified below: add the table pages
        sta _shl+2
        txa
        lsr
        lsr
        lsr
        sta k
        lda #3
        sec
        sbc k
        sta nb
        lda _shr+2
        clc
        adc #>pixel_shr
        sta _shr+2
        lda _shl+2
        clc
        adc #>pixel_shl
        sta _shl+2
        lda sdy
        bmi _up
        cmp #21                 ; second mask lower: first's rows dy.., second's rows 0..
        bcs _miss
        sta rows
        asl
        adc rows                ; 3 * dy
        adc k
        sta pa
        lda #0
        sta pb
        beq _count
_up:    eor #$ff                ; second mask higher by -dy rows
        clc
        adc #1
        cmp #21
        bcs _miss
        sta rows
        asl
        adc rows
        sta pb
        lda k
        sta pa
_count: lda #21
        sec
        sbc rows
        sta rows
        ldy #0
_row:   lda #0
        sta prev
        tya
        clc
        adc nb
        sta endm
_byte:  lda (pb),y
        tax
_shr:   lda pixel_shr,x
        ora prev
        and (pa),y
        bne _hit
_shl:   lda pixel_shl,x
        sta prev
        iny
        cpy endm
        bne _byte
        tya
        clc
        adc k
        tay
        dec rows
        bne _row
_miss:  clc
        rts
_hit:   sec
        rts
