; every kind of symbol ca65 2.19 / ld65 write to --dbgfile and -Ln
.export start, DELTA, WIDE, boxa_x, FORWARD
.exportzp counter
DELTA   = -16                   ; negative: 0xFFFFFFF0 in both files
WIDE    = $12345                ; wider than 16 bits
boxa_x  = $fb                   ; a zero-page equate
.define TITLE "hi"              ; a define: in neither file
.segment "ZEROPAGE"
counter: .res 1                 ; reserved in zero page
.segment "CODE"
start:  lda boxa_x
        ldx #<DELTA
@cheap: dex                     ; a cheap local: start's @cheap
        bne @cheap
:       dey                     ; an unnamed label: in neither file
        bne :-
        jsr later
        lda FORWARD
        rts
.proc later
loop:   dex                     ; later::loop
        bne loop
        rts
.endproc
.scope outer
.proc inner
deep:   nop                     ; outer::inner::deep
        rts
.endproc
.endscope
FORWARD = $0400                 ; defined after its use
.struct Point                   ; struct members: offsets, scope Point
  xc .byte
  yc .byte
.endstruct
.enum Color                     ; enum members: constants, scope Color
  red
  green = 5
.endenum
