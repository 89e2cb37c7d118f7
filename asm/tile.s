; tile: the property byte of the screen cell under a point given in C64 sprite coordinates.
;
; In (registers):  X = x low byte, Y = y, C = x high bit (the sprite's $D010 bit; e.g.
;      LDA $D010 / AND #bit / CMP #1 sets it, or LSR for sprite 0).
; Out: A = tile_props[screen code of the cell] (Z set when it is 0); A = 0 when the point is
;      outside the 40 x 25 text screen. X, Y, C: undefined. Uses $13/$14 as a pointer.
; The point (x, y) in sprite coordinates is screen pixel (x - 24, y - 50); the cell is
;      column (x - 24) / 8, row (y - 50) / 8 of the screen at $0400 (retro.routines.screen).
; Method: tables indexed by the raw coordinate do the offset, the division and the bounds
;      check at once: tile_rowlo/hi[y] = address of the cell row (high byte 0 = off screen),
;      tile_col0[x] / tile_col1[x] (for $D010 bit 0 / 1) = column or $FF (off screen). The 9-bit
;      X costs one branch on the carry, which no instruction before it changes.
; tile_props: 256 bytes, one per screen code (bit meanings are the game's: solid, hazard,
;      ladder...); the game (or `retro check`) fills it.
; Domain: every 9-bit x and 8-bit y, any screen content.
        .org $c000
        .alias ptr $13
; retro-tables: tile_rowlo tile_rowhi tile_col0 tile_col1 tile_props

tile:
        lda tile_rowhi,y
        beq _off
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
