; lookup: A = levels[X], or $FF when that byte has bit 7 set (a test fixture for stated facts: the
; levels are made by a generator, so the static analysis cannot know their values).
; Cycles: LDA abs,X 4 (levels at $C100, X < 16: no crossing), BMI not taken 2, RTS 6 = 12;
; BMI taken 3, LDA # 2, NOP 2, RTS 6 = 4 + 3 + 2 + 2 + 6 = 17.
        .org $c000
        .alias levels $c100

lookup: lda levels,x
check:  bmi negative
        rts
negative:
        lda #$ff
        nop
        rts
