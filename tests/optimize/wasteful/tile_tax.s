; tile_tax: a deliberately wasteful version of asm/tile.s with a store and a load where TAX does.
;
; The optimiser must reach asm/tile.s's cost (tests/optimize/test_wasteful.py).
        .org $c000
        .alias ptr $13
        .alias tmp $15
; retro-tables: tile_rowlo tile_rowhi tile_col0 tile_col1 tile_props

tile_tax:
        lda tile_rowhi,y
        beq _off
        sta ptr+1
        lda tile_rowlo,y
        sta ptr
        bcs _right
        ldy tile_col0,x
        bmi _off
_read:  lda (ptr),y
        sta tmp                 ; waste: TAX does it
        ldx tmp
        lda tile_props,x
        rts
_right: ldy tile_col1,x
        bpl _read
_off:   lda #0
        rts
