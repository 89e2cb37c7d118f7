; aabb_sprite: do two sprite hitboxes overlap? C64 sprite coordinates: 9-bit X ($D010 bit), 8-bit Y,
; each hitbox given as an offset and a size inside its sprite.
;
; In (zero page):  sprite 1: $10 x low  $11 x high bit (0/1)  $12 y
;                            $13 hit x offset  $14 hit y offset  $15 hit width  $16 hit height
;                  sprite 2: $18 x low  $19 x high bit  $1a y  $1b hx  $1c hy  $1d hw  $1e hh
;      Hitbox of sprite n: pixels x+hx .. x+hx+hw-1, y+hy .. y+hy+hh-1 (sprite coordinates).
; Out: carry set = the hitboxes share a pixel; carry clear = they do not. A, Y: undefined; X kept.
; Edge convention (as aabb8 and retro.geometry): touching hitboxes do NOT overlap.
; Method: per axis, e = (p2 + o2) - (p1 + o1) is formed with the high byte counted in Y (the
;      low byte in A, each carry an INY/DEY), so 9-bit X, offsets and sums past 255 are exact;
;      then -size2 < e < size1 is tested on the one or two possible high bytes.
; Domain: every input with sizes >= 1 (`retro check aabb_sprite` reports the exact domain).
        .org $c000
        .alias x1  $10
        .alias x1h $11
        .alias y1  $12
        .alias ox1 $13
        .alias oy1 $14
        .alias w1  $15
        .alias h1  $16
        .alias x2  $18
        .alias x2h $19
        .alias y2  $1a
        .alias ox2 $1b
        .alias oy2 $1c
        .alias w2  $1d
        .alias h2  $1e

aabb_sprite:
        ldy x2h
        lda x2
        clc
        adc ox2
        bcc +
        iny
*       sec
        sbc x1
        bcs +
        dey
        sec
*       sbc ox1
        bcs +
        dey
*       cpy x1h
        bne _x_left
        cmp w1                  ; 0 <= e < 256: overlap needs e < w1
        bcc _y
_miss:  clc
        rts
_x_left:
        iny
        cpy x1h
        bne _miss               ; e < -256 or e >= 256
        clc
        adc w2                  ; e = A - 256: overlap needs A + w2 > 256
        beq _miss
        bcc _miss
_y:     ldy #0
        lda y2
        clc
        adc oy2
        bcc +
        iny
*       sec
        sbc y1
        bcs +
        dey
        sec
*       sbc oy1
        bcs +
        dey
*       cpy #0
        bne _y_up
        eor #$ff                ; 0 <= e < 256: overlap needs h1 > e, i.e. h1 + ~e >= 256
        clc
        adc h1
        rts
_y_up:  iny
        bne _miss
        clc
        adc h2                  ; e = A - 256: overlap needs A + h2 > 256
        beq _miss
        rts
