; umin: A = the smaller of A and m (unsigned). The textbook way: compare, keep A when it is smaller.
        .org $c000
.alias m $fb                ; the second operand, in zero page
umin:   cmp m
        bcc done
        lda m
done:   rts
