; every kind of line xa 2.3.14 writes with -l (and with -r, the lines that use each label)
; (no colons in these comments, xa reads a colon as the end of a statement)
        *= $c000
boxa_x  = $fb                   ; a zero-page equate
DELTA   = -128                  ; negative, written 0xffffff80
WIDE    = $12345                ; wider than 16 bits
start   lda boxa_x
        jsr later
        .(
loop    dex                     ; block 1's loop
        bne loop
        .)
later   .(
&shared nop                     ; & makes a global inside a block
loop    dey                     ; block 2's loop
        bne loop
        rts
        .)
FORWARD = $0400
        lda FORWARD
