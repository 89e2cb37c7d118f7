; umax: A = the larger of A and m (unsigned). The textbook way: compare, keep A when it is larger.
        .org $c000
.alias m $fb                ; the second operand, in zero page
umax:   cmp m
        bcs done
        lda m
done:   rts

