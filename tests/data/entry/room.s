; room: how many bytes of stack are free below the return address, from the stack pointer at a
; fixed place: right only when the caller calls it with an empty stack.
        .org $c000
room:
        tsx
        stx free
        lda key
        sta echo
        rts
key:    .byte 0
echo:   .byte 0
free:   .byte 0
