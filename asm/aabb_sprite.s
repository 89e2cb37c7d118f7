; aabb_sprite: do two sprite hitboxes overlap? C64 sprite coordinates: 9-bit X ($D010 bit), 8-bit Y,
; each hitbox given as an offset and a size inside its sprite.
;
; In:  sprite 2's X in registers as a game holds it: A = x2 low byte, C = x2h ($D010 bit, e.g.
;      LDA $D010 / AND #bit / CMP #1), Y = y2; X = x1h (sprite 1's $D010 bit, 0 or 1).
;      Zero page: $10 x1 (low byte)  $11 y1  $12 ox1  $13 oy1  $14 w1  $15 h1   (sprite 1)
;                 $16 ox2  $17 oy2  $18 w2  $19 h2                                (sprite 2)
;      Hitbox of sprite n: pixels xn+256*xnh+oxn .. +wn-1, yn+oyn .. +hn-1 (sprite coordinates).
; Out: carry set = the hitboxes share a pixel; carry clear = they do not. A, X: undefined; Y kept.
; Edge convention (as aabb8 and retro.geometry): touching hitboxes do NOT overlap.
; Method: per axis d = (p2 + o2) - (p1 + o1) (x: with 256 * (x2h - x1h)) is summed in A one byte
;      at a time; each carry, borrow and $D010 bit is a branch, and the branches lead to copies of
;      the rest of the sum that know the high part of d and the +-1 left by a carry they did not
;      reset (the program counter holds them, so no INY/DEY, CLC or SEC is paid for them). At the
;      end only high part 0 (0 <= d < 256: overlap iff d < w1) or -1 (overlap iff d > -w2) can
;      overlap, and each copy does the one compare its state needs. The blocks are laid out by
;      asm/generate/aabb_sprite.py (a search over the orders of the terms); each block's comment
;      gives its state (terms left, high part, offset, carry) and the worst case from its first
;      instruction as that search counted it, i.e. without the 13 `bXX _tN / jmp` detours that
;      keep branches in range (they add up to 6 cycles to some paths).
; Cost: 31-70 cycles (static 31-70, reached), no tables: the sum is 4 terms on x (3 carries and 2
;      $D010 bits decide the high part) and 4 on y (3 carries), each a read and a branch.
; Domain: every input with x1h, x2h in 0/1 and sizes >= 1 (`retro check aabb_sprite`).
        .org $c000
        .alias x1  $10
        .alias y1  $11
        .alias ox1 $12
        .alias oy1 $13
        .alias w1  $14
        .alias h1  $15
        .alias ox2 $16
        .alias oy2 $17
        .alias w2  $18
        .alias h2  $19

aabb_sprite:
        bcc _t1
        jmp _x0
_t1:
_x1:                      ; x: left ox1,ox2,x1,x1h; high 0, offset 0, C=0; worst 62
        dex                     ; x1h: 1 -> Z
        beq _x2
_x3:                      ; x: left ox1,ox2,x1; high 0, offset 0, C=0; worst 58
        sbc ox1
        bcs _x4
_x5:                      ; x: left ox2,x1; high -1, offset -1, C=0; worst 53
        sbc x1
        bcc _x6
_x7:                      ; x: left ox2; high -1, offset -2, C=1; worst 48
        adc ox2
        bcc _x8
_x9:                      ; x: left -; high 0, offset -1, C=1; worst 43
        adc #0
        bcs _miss
_x10:                      ; x: left -; high 0, offset 0, C=0; worst 39
        cmp w1
        bcc _ystart0
        clc
        rts
_x8:                      ; x: left -; high -1, offset -1, C=0; worst 38
        adc w2
        bcs _ystart1
        rts
_x6:                      ; x: left ox2; high -2, offset -2, C=0; worst 47
        sec
_x11:                      ; x: left ox2; high -2, offset -2, C=1; worst 45
        adc ox2
        bcc _out
_x12:                      ; x: left -; high -1, offset -1, C=1; worst 40
        clc
_x13:                      ; x: left -; high -1, offset -1, C=0; worst 38
        adc w2
        bcs _ystart1
        rts
_x4:                      ; x: left ox2,x1; high 0, offset -1, C=1; worst 52
        sbc x1
        bcs _x14
_x15:                      ; x: left ox2; high -1, offset -1, C=0; worst 47
        sec
_x16:                      ; x: left ox2; high -1, offset -1, C=1; worst 45
        adc ox2
        bcs _x17
_x18:                      ; x: left -; high -1, offset 0, C=0; worst 40
        adc w2
        bcc _out
        bne _ystart1
        clc
        rts
_x17:                      ; x: left -; high 0, offset 0, C=1; worst 39
        cmp w1
        bcc _ystart0
        clc
        rts
_x14:                      ; x: left ox2; high 0, offset -1, C=1; worst 44
        adc ox2
        bcs _miss
_x19:                      ; x: left -; high 0, offset 0, C=0; worst 39
        cmp w1
        bcc _ystart0
        clc
        rts
_x2:                      ; x: left ox1,ox2,x1; high -1, offset 0, C=0; worst 56
        sbc ox1
        bcc _x20
_x21:                      ; x: left ox2,x1; high -1, offset -1, C=1; worst 51
        sbc x1
        bcc _x22
_x23:                      ; x: left ox2; high -1, offset -1, C=1; worst 45
        adc ox2
        bcs _x24
_x25:                      ; x: left -; high -1, offset 0, C=0; worst 40
        adc w2
        bcc _out
        bne _ystart1
        clc
        rts
_x24:                      ; x: left -; high 0, offset 0, C=1; worst 39
        cmp w1
        bcc _ystart0
        clc
        rts
_x22:                      ; x: left ox2; high -2, offset -1, C=0; worst 45
        adc ox2
        bcc _out
_x26:                      ; x: left -; high -1, offset -1, C=1; worst 40
        clc
_x27:                      ; x: left -; high -1, offset -1, C=0; worst 38
        adc w2
        bcs _ystart1
        rts
_x20:                      ; x: left ox2,x1; high -2, offset -1, C=0; worst 50
        sbc x1
        bcc _x28
_x29:                      ; x: left ox2; high -2, offset -2, C=1; worst 45
        adc ox2
        bcc _out
_x26_1:                      ; x: left -; high -1, offset -1, C=1; worst 40
        clc
_x27_2:                      ; x: left -; high -1, offset -1, C=0; worst 38
        adc w2
        bcs _ystart1
        rts
_x28:                      ; x: left ox2; high -3, offset -2, C=0; worst 13
        adc ox2
        bcc _out
        clc
        rts
_miss:  clc
_out:   rts
_ystart0:
        tya                     ; A = y2
_y30:                      ; y: left oy1,oy2,y1; high 0, offset 0, C=0; worst 31
        sbc oy1
        bcc _y31
_y32:                      ; y: left oy2,y1; high 0, offset -1, C=1; worst 25
        adc oy2
        bcs _y33
_y34:                      ; y: left y1; high 0, offset 0, C=0; worst 20
        sbc y1
        bcc _y35
_y36:                      ; y: left -; high 0, offset -1, C=1; worst 15
        adc #0
        bcs _miss
_y37:                      ; y: left -; high 0, offset 0, C=0; worst 11
        eor #$ff
        adc h1
        rts
_ystart1:
        tya                     ; A = y2
_y38:                      ; y: left oy1,oy2,y1; high 0, offset 0, C=1; worst 30
        sbc oy1
        bcc _y39
_y40:                      ; y: left oy2,y1; high 0, offset 0, C=1; worst 24
        adc oy2
        bcs _y41
_y42:                      ; y: left y1; high 0, offset 1, C=0; worst 19
        sbc y1
        bcs _y43
_y44:                      ; y: left -; high -1, offset 0, C=0; worst 14
        adc h2
        beq _miss
        rts
_y43:                      ; y: left -; high 0, offset 0, C=1; worst 13
        clc
_y37_3:                      ; y: left -; high 0, offset 0, C=0; worst 11
        eor #$ff
        adc h1
        rts
_y41:                      ; y: left y1; high 1, offset 1, C=1; worst 18
        clc
_y45:                      ; y: left y1; high 1, offset 1, C=0; worst 16
        sbc y1
        bcs _miss
_y37_4:                      ; y: left -; high 0, offset 0, C=0; worst 11
        eor #$ff
        adc h1
        rts
_y39:                      ; y: left oy2,y1; high -1, offset 0, C=0; worst 24
        adc oy2
        bcc _y46
_y47:                      ; y: left y1; high 0, offset 0, C=1; worst 19
        sbc y1
        bcs _y43
_y44_5:                      ; y: left -; high -1, offset 0, C=0; worst 14
        adc h2
        beq _miss
        rts
_y46:                      ; y: left y1; high -1, offset 0, C=0; worst 16
        sbc y1
        bcc _out
_y48:                      ; y: left -; high -1, offset -1, C=1; worst 11
        clc
_y49:                      ; y: left -; high -1, offset -1, C=0; worst 9
        adc h2
        rts
_y35:                      ; y: left -; high -1, offset -1, C=0; worst 9
        adc h2
        rts
_y33:                      ; y: left y1; high 1, offset 0, C=1; worst 16
        sbc y1
        bcs _miss
_y50:                      ; y: left -; high 0, offset 0, C=0; worst 11
        eor #$ff
        adc h1
        rts
_y31:                      ; y: left oy2,y1; high -1, offset -1, C=0; worst 25
        adc oy2
        bcc _y51
_y52:                      ; y: left y1; high 0, offset -1, C=1; worst 20
        sbc y1
        bcc _y35
_y36_6:                      ; y: left -; high 0, offset -1, C=1; worst 15
        adc #0
        bcs _miss
_y37_7:                      ; y: left -; high 0, offset 0, C=0; worst 11
        eor #$ff
        adc h1
        rts
_y51:                      ; y: left y1; high -1, offset -1, C=0; worst 18
        sec
_y53:                      ; y: left y1; high -1, offset -1, C=1; worst 16
        sbc y1
        bcc _out
_y54:                      ; y: left -; high -1, offset -1, C=1; worst 11
        clc
_y55:                      ; y: left -; high -1, offset -1, C=0; worst 9
        adc h2
        rts
_x0:                      ; x: left ox1,ox2,x1,x1h; high 1, offset 0, C=1; worst 61
        sbc ox1
        bcs _x56
_x57:                      ; x: left ox2,x1,x1h; high 0, offset 0, C=0; worst 56
        dex                     ; x1h: 1 -> Z
        beq _x58
_x59:                      ; x: left ox2,x1; high 0, offset 0, C=0; worst 52
        sbc x1
        bcc _t2
        jmp _x14
_t2:
_x15_8:                      ; x: left ox2; high -1, offset -1, C=0; worst 47
        sec
_x16_9:                      ; x: left ox2; high -1, offset -1, C=1; worst 45
        adc ox2
        bcc _t3
        jmp _x17
_t3:
_x18_10:                      ; x: left -; high -1, offset 0, C=0; worst 40
        adc w2
        bcs _t4
        jmp _out
_t4:
        bne _ystart1
        clc
        rts
_x58:                      ; x: left ox2,x1; high -1, offset 0, C=0; worst 51
        sbc x1
        bcs _t5
        jmp _x22
_t5:
_x23_11:                      ; x: left ox2; high -1, offset -1, C=1; worst 45
        adc ox2
        bcc _t6
        jmp _x24
_t6:
_x25_12:                      ; x: left -; high -1, offset 0, C=0; worst 40
        adc w2
        bcs _t7
        jmp _out
_t7:
        beq _t8
        jmp _ystart1
_t8:
        clc
        rts
_x56:                      ; x: left ox2,x1,x1h; high 1, offset 0, C=1; worst 55
        dex                     ; x1h: 1 -> Z
        bne _x60
_x61:                      ; x: left ox2,x1; high 0, offset 0, C=1; worst 51
        sbc x1
        bcc _x62
_x63:                      ; x: left ox2; high 0, offset 0, C=1; worst 46
        clc
_x64:                      ; x: left ox2; high 0, offset 0, C=0; worst 44
        adc ox2
        bcs _miss2
_x10_13:                      ; x: left -; high 0, offset 0, C=0; worst 39
        cmp w1
        bcs _t9
        jmp _ystart0
_t9:
        clc
        rts
_x62:                      ; x: left ox2; high -1, offset 0, C=0; worst 45
        adc ox2
        bcc _t10
        jmp _x24
_t10:
_x25_14:                      ; x: left -; high -1, offset 0, C=0; worst 40
        adc w2
        bcs _t11
        jmp _out
_t11:
        beq _t12
        jmp _ystart1
_t12:
        clc
        rts
_x60:                      ; x: left ox2,x1; high 1, offset 0, C=1; worst 49
        sbc x1
        bcs _x65
_x66:                      ; x: left ox2; high 0, offset 0, C=0; worst 44
        adc ox2
        bcs _miss2
_x19_15:                      ; x: left -; high 0, offset 0, C=0; worst 39
        cmp w1
        bcs _t13
        jmp _ystart0
_t13:
        clc
        rts
_x65:                      ; x: left ox2; high 1, offset 0, C=1; worst 13
        adc ox2
        bcc _out2
        clc
        rts
_miss2: clc
_out2:  rts
