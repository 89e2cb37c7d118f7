; tile_box: OR of the property bytes of every screen cell a hitbox touches (C64 sprite coords).
;
; In (zero page):  $10 x low byte  $11 x high bit ($D010 bit: 0 or 1)  $12 y  $13 w  $14 h
;      The box covers sprite-coordinate pixels x .. x+w-1, y .. y+h-1 (w or h = 0: no pixels).
; Out: A = OR of tile_props[code] over the on-screen cells the box touches (0 when none; Z set
;      accordingly). X, Y, C: undefined. Uses $15-$1B.
; Cells off the 40 x 25 screen are ignored (they contribute nothing).
; Method: first/end column and row come from tables indexed by the raw coordinate (offsets 24/50,
;      division by 8 and clamping to the screen at once); then a row loop sets a pointer from the
;      row-address table and a column loop ORs the properties.
; Loop bounds (for the static analysis): _row runs at most 25 times, _col at most 40 per row.
; Domain: every input.
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

tile_box:
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
