; sprite_edges: do two C64 sprite hitboxes overlap, from edges prepared once per sprite per frame
; (sprite_edges_prepare folds the hitbox offsets into a 9-bit left edge and an 8-bit top).
;
; In:  registers A = sprite A's left edge, low byte; X = its top; Y = its bottom - 1 (last row);
;      zero page $10 a_left_hi, $11 a_right, $12 a_right_hi (right = left + width, 16-bit),
;      $13 b_left, $14 b_left_hi, $15 b_right, $16 b_right_hi, $17 b_top, $18 b_bottom (top + height).
; Out: carry set = the hitboxes share at least one pixel; clear = they do not. A: undefined;
;      X, Y and the zero page preserved.
; Edge convention (as retro.geometry): half-open boxes; hitboxes that touch do NOT overlap.
; Method: two 16-bit "left < other's right" tests (CMP the low bytes, SBC the high bytes: the
;      borrow is the answer), then the 8-bit rows as in aabb_edges; the last CPY leaves the answer
;      in the carry for the RTS.
; Domain: edges of hitboxes with width, height >= 1 whose bottom fits in a byte (top + height <= 255);
;      any 9-bit X (the right edge may pass 511: it is 16-bit).
; Cost: 20-39 cycles (static 20-39; 39 on a hit). sprite_edges_prepare: 68 cycles.
        .org $c000
        .alias a_left_hi  $10
        .alias a_right    $11
        .alias a_right_hi $12
        .alias b_left     $13
        .alias b_left_hi  $14
        .alias b_right    $15
        .alias b_right_hi $16
        .alias b_top      $17
        .alias b_bottom   $18

sprite_edges:
        cmp b_right             ; a_left - b_right, 16-bit: C = a_left >= b_right (miss)
        lda a_left_hi
        sbc b_right_hi
        bcs _miss
        lda b_left              ; b_left - a_right: C = b_left >= a_right (miss)
        cmp a_right
        lda b_left_hi
        sbc a_right_hi
        bcs _miss
        cpx b_bottom            ; C = a_top >= b_bottom (miss)
        bcs _miss
        cpy b_top               ; C = a_bottom1 >= b_top: the answer
        rts
_miss:  clc
        rts

; sprite_edges_prepare: a sprite's edges from its position and hitbox.
; In:  zero page $20 sx (X low byte), $21 sxh (the $D010 bit), $22 sy, $23 ox, $24 oy, $25 w, $26 h:
;      the hitbox covers X sx + 256 sxh + ox .. + w - 1 and rows sy + oy .. + h - 1.
; Out: zero page $27 left, $28 left_hi, $29 right, $2a right_hi, $2b top, $2c bottom, $2d bottom1.
        .alias sx $20
        .alias sxh $21
        .alias sy $22
        .alias ox $23
        .alias oy $24
        .alias w $25
        .alias h $26
        .alias e_left $27
        .alias e_left_hi $28
        .alias e_right $29
        .alias e_right_hi $2a
        .alias e_top $2b
        .alias e_bottom $2c
        .alias e_bottom1 $2d

sprite_edges_prepare:
        lda sx
        clc
        adc ox
        sta e_left
        lda sxh
        adc #0
        sta e_left_hi
        lda e_left
        clc
        adc w
        sta e_right
        lda e_left_hi
        adc #0
        sta e_right_hi
        lda sy
        clc
        adc oy
        sta e_top
        clc
        adc h
        sta e_bottom
        sbc #0                  ; C clear in the domain: bottom - 1
        sta e_bottom1
        rts
