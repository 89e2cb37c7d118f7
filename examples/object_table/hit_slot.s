; hit_slot: does the player's 8 x 8 box overlap the box of object X? The objects live in a
; struct-of-arrays table, as most 6502 games keep them (Super Mario Bros., Atari and NES homebrew):
; one array per field (obj_x, obj_y), indexed by the object's slot in X.
;
; In:  X = slot (0-7), obj_x,X and obj_y,X its position, player_x ($FB) and player_y ($FC).
; Out: C set when the boxes overlap (|dx| < 8 and |dy| < 8, positions taken modulo 256).
; Cost: 26 cycles on a miss along x, 43 on a miss along y, 42 on a hit (RTS included; one more
;       where obj_x,X or obj_y,X crosses a page).
        .org $c000
        .alias player_x $fb
        .alias player_y $fc

hit_slot:
        lda obj_x,x
        sec
        sbc player_x    ; dx = object - player
        clc
        adc #7          ; |dx| < 8  <=>  dx + 7 in 0..14
        cmp #15
        bcs miss
        lda obj_y,x
        sec
        sbc player_y
        clc
        adc #7
        cmp #15
        bcs miss
        sec             ; both within 7: a hit
        rts
miss:   clc
        rts

obj_x:  .byte 0, 0, 0, 0, 0, 0, 0, 0
obj_y:  .byte 0, 0, 0, 0, 0, 0, 0, 0
