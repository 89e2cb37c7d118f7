; absdiff: A = |first - second|, two bytes the caller pushed before its JSR (a common way to pass
; arguments when registers run short):
;
;       lda first : pha
;       lda second : pha
;       jsr absdiff
;       tax : pla : pla : txa   ; the caller drops its arguments
;
; After the JSR, S points below the return address: $0101,X and $0102,X (X = S) hold the return
; address, $0103,X the byte pushed last (second), $0104,X the one before it (first).
; Cost: 21 cycles when first >= second, 24 otherwise (RTS included).
        .org $c000

absdiff:
        tsx
        lda $0104,x     ; first
        sec
        sbc $0103,x     ; - second
        bcs done
        eor #$ff        ; negative: negate (C is clear here, so ADC #1 adds exactly 1)
        adc #1
done:   rts
