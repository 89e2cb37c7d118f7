; join: A = X + b, with a branch over an instruction that rejoins after it: the carry is clear at
; the branch, so it is always taken and the CLC it skips is dead; nothing of the two is needed (a
; window that spans a branch and its join; tests/optimize/test_wasteful.py).
        .org $c000
join:
        txa
        clc
        bcc join2               ; waste: always taken
        clc
join2:  adc b_val
        rts
b_val:  .byte 0
