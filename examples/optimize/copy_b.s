; copy_b: A = b. A fixture of the optimiser's tests: candidates that rely on the entry state. The
; data comes first, so that a longer candidate written over the code overwrites nothing.
        .org $c000
b_val:  .byte 0
copy_b: lda b_val
        rts
