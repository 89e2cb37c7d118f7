; tile_reload: a deliberately wasteful version of asm/tile.s reading a table entry again through the index: A holds
; tile_rowhi,y already.
;
; The optimiser must reach asm/tile.s's cost (tests/optimize/test_wasteful.py).
        .org $c000
        .alias ptr $13
; retro-tables: tile_rowlo tile_rowhi tile_col0 tile_col1 tile_props

tile_reload:
        lda tile_rowhi,y
        beq _off
        lda tile_rowhi,y        ; waste: A holds it
        sta ptr+1
        lda tile_rowlo,y
        sta ptr
        bcs _right
        ldy tile_col0,x
        bmi _off
_read:  lda (ptr),y
        tax
        lda tile_props,x
        rts
_right: ldy tile_col1,x
        bpl _read
_off:   lda #0
        rts
