; every kind of line ACME 0.97 writes with --symbollist and --vicelabels
!cpu 6502
* = $c000
boxa_x  = $fb                   ; a zero-page equate, read
DELTA   = -128                  ; negative: written as the 32-bit $ffffff80
WIDE    = $12345                ; wider than 16 bits
RATIO   = 3.25                  ; a float
LETTER  = 'A'                   ; a character: the number $41
!set COUNT = 3                  ; !set
!addr SCREEN = $0400            ; an address equate
ptr+2   = $fb                   ; a forced 16-bit width: `ptr+2 = $fb`
start   lda boxa_x
        lda ptr
        lda SCREEN
        ldx #DELTA & $ff
        jsr later               ; a forward reference: `; ?` in the list
.loop   dex                     ; a zone local: not in either file
        bne .loop
        rts
!zone later
later   lda #<FORWARD           ; FORWARD is defined below: `; ?`
        rts
FORWARD = $0400
unused  nop                     ; never referenced: `; unused`
