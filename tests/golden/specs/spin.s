        .org $c000
entry:  cmp #$c8
        bne ok
spin:   jmp spin
ok:     rts
