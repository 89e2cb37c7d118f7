        .org $c000
entry:  cmp #$c8
        bne ok
        .byte $02
ok:     rts
