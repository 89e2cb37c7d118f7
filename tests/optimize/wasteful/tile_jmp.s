; tile_jmp: a deliberately wasteful version of asm/tile.s with a branch that could fall through: BCC over a JMP instead of one BCS.
;
; The optimiser must reach asm/tile.s's cost (tests/optimize/test_wasteful.py).
        .org $c000
        .alias ptr $13
; retro-tables: tile_rowlo tile_rowhi tile_col0 tile_col1 tile_props

tile_jmp:
        lda tile_rowhi,y
        beq _off
        sta ptr+1
        lda tile_rowlo,y
        sta ptr
        bcc _left               ; waste: BCS _right falls through
        jmp _right
_left:
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
