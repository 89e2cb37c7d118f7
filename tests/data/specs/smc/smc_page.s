; smc_page: entry y of the table at page `tables` + A, the page patched into the high byte of the
; read's operand (a test fixture of self-modifying code, written for retro's tests).
; In: A = table number, Y = index. Out: A = the byte.
; Cycles: CLC 2, ADC # 2, STA abs 4, LDA abs,Y 4 (+1 when $80 + Y crosses a page: Y >= $80), RTS 6
; = 18-19. Whatever page A picks, the low byte of the operand stays $80.
        .org $c000
        .alias tables $c100

smc_page:
        clc
        adc #>tables
        sta read+2
read:   lda tables+$80,y
        rts
