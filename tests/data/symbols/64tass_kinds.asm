; every kind of value 64tass 1.58 writes with -l, --vice-labels(-numeric) and --dump-labels
        *= $c000
boxa_x  = $fb                   ; a zero-page equate
DELTA   = -128                  ; negative integer: -128
MASK    = -$80                  ; negative bits: ~$7f
WIDE    = $12345                ; wider than 16 bits
HUGE    = 2**200                ; 64tass integers have no size limit
DECIMAL = $c000+1               ; an integer result: written in decimal, 49153
RATIO   = 3.25                  ; a float
TINY    = 1e-5                  ; a float in exponent form
TITLE   = "hi;there"            ; a string (with a `;` in it)
LETTER  = 'A'                   ; a one-character string
TABLE   = [1, 2, 3]             ; a list
PAIR    = (1, 2)                ; a tuple
MAP     = {1: 2}                ; a dictionary
FLAG    = true                  ; a boolean
BYTES   = x"0102"               ; bytes: written z85-encoded, z'...'
GAP     = ?                     ; a gap: no value
REG     = a                     ; a register
COUNT  := 5                     ; a variable: `:=`
start   lda boxa_x
        jsr later
_loop   dex                     ; a cheap local of start: start._loop / start:_loop
        bne _loop
-       dey                     ; an anonymous label: in no file
        bne -
        rts
later   .block
loop    dex                     ; later.loop / later:loop
        bne loop
        rts
        .bend
        .logical $0400
moved   nop                     ; an address in a .logical block
        .here
