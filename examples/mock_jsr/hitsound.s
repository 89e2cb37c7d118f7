; hitsound: two objects 8 pixels wide touch when |ax - bx| < 8; on a touch the game asks the music
; player for its hit sound (JSR to the player's sound-effect entry, which is not part of this
; program: hitsound.toml says what it does, as a mock) and returns C set.
;
; In:  $FB = ax, $FC = bx (x positions, 0-255).
; Out: C = 1 when they touch; the player's sfx entry called once with A = 2 (the hit sound) then.
        .org $c000
        .alias ax       $fb
        .alias bx       $fc
        .alias play_sfx $1003   ; the music player's "play sound effect A" entry (loaded elsewhere)
        .alias hit_sound 2

hit:    lda ax
        sec
        sbc bx
        bcs apart       ; ax >= bx: A = ax - bx
        eor #$ff        ; ax < bx: A = bx - ax (two's complement of the difference)
        adc #1
apart:  cmp #8
        bcs miss
        lda #hit_sound
        jsr play_sfx    ; the player keeps X and Y; it returns with C clear
        sec
        rts
miss:   clc
        rts
