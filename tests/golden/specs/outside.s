        .org $c000
entry:  cmp #$c8
        bcc done
        nop
done:   rts
