; tile_box_reload: a deliberately wasteful version of asm/tile_box.s reading a table entry again through X: A holds
; tbox_rfirst,x already (an indexed window on a sampled proof).
;
; The optimiser must reach asm/tile_box.s's cost (tests/optimize/test_wasteful.py).
        .org $c000
        .alias bx   $10
        .alias bxh  $11
        .alias by   $12
        .alias bw   $13
        .alias bh   $14
        .alias ptr  $15
        .alias c0   $17
        .alias c1   $18
        .alias r1   $19
        .alias acc  $1a
        .alias row  $1b
; retro-tables: tbox_cfirst0 tbox_cfirst1 tbox_cend0 tbox_cend1 tbox_rfirst tbox_rend0 tbox_rend1 tbox_rowlo tbox_rowhi tile_props

tile_box_reload:
        lda #0
        sta acc
        ; columns: c0 = first column, c1 = one past the last (both clamped to 0..40)
        ldx bx
        lda bxh
        bne _xhi
        lda tbox_cfirst0,x
        sta c0
        txa
        clc
        adc bw                  ; end pixel x + w (exclusive), 10 bits: high part 0 or 1 here
        tax
        bcs _e1
        lda tbox_cend0,x
        jmp _cend
_xhi:   lda tbox_cfirst1,x
        sta c0
        txa
        clc
        adc bw
        tax
        bcs _cfull              ; x + w >= 512: past the right edge
_e1:    lda tbox_cend1,x
        jmp _cend
_cfull: lda #40
_cend:  sta c1
        cmp c0
        beq _none
        bcc _none
        ; rows: row = first row, r1 = one past the last
        ldx by
        lda tbox_rfirst,x
        sta row
        lda tbox_rfirst,x       ; waste: A holds it
        txa
        clc
        adc bh
        tax
        bcs _r1
        lda tbox_rend0,x
        jmp _rend
_r1:    lda tbox_rend1,x
_rend:  sta r1
        cmp row
        beq _none
        bcc _none
_row:   ldx row
        lda tbox_rowlo,x
        sta ptr
        lda tbox_rowhi,x
        sta ptr+1
        ldy c0
_col:   lda (ptr),y
        tax
        lda tile_props,x
        ora acc
        sta acc
        iny
        cpy c1
        bne _col
        inc row
        lda row
        cmp r1
        bne _row
        lda acc
        rts
_none:  lda #0
        rts
