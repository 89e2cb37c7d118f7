        .org $c000
entry:  cmp #$c8
        bne ok
        brk
ok:     rts
