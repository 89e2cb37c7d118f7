; clamp: A = min(A, 199), a sprite's Y kept on the screen. The textbook way: compare, replace.
        .org $c000
clamp:  cmp #200
        bcc done
        lda #199
done:   rts
