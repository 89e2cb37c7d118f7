; tile_cmp: a deliberately wasteful version of asm/tile.s with a compare whose flags the load already holds: CPY #0 after LDY.
;
; The optimiser must reach asm/tile.s's cost (tests/optimize/test_wasteful.py).
        .org $c000
        .alias ptr $13
; retro-tables: tile_rowlo tile_rowhi tile_col0 tile_col1 tile_props

tile_cmp:
        lda tile_rowhi,y
        beq _off
        sta ptr+1
        lda tile_rowlo,y
        sta ptr
        bcs _right
        ldy tile_col0,x
        cpy #0                  ; waste: LDY set N already
        bmi _off
_read:  lda (ptr),y
        tax
        lda tile_props,x
        rts
_right: ldy tile_col1,x
        bpl _read
_off:   lda #0
        rts
