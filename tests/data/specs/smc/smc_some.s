; smc_some: patches the low byte of its read's operand on one path only (carry set: $FF), so the
; read's page crossing depends on the path (a test fixture of self-modifying code).
; In: C, X. Out: A = the byte read (the spec fills the page with zeros).
; Cycles with X = 1: carry clear: BCC taken 3, LDA $C200,X 4 (no crossing: $00 + 1), RTS 6 = 13;
; carry set: BCC 2, LDA # 2, STA abs 4, LDA $C2FF,X 5 (crosses), RTS 6 = 19.
        .org $c000

smc_some:
        bcc read
        lda #$ff
        sta read+1
read:   lda $c200,x
        rts
