; in_span: does a coordinate lie outside a span whose record the caller points to? The record is
; two bytes behind the zero-page pointer `span` ($FB/$FC): the span's left edge, then its width.
;
; In:  A = coordinate; (span) = left, (span)+1 = width.
; Out: C clear when left <= A < left + width (A - left < width, no wrap), set otherwise.
        .org $c000
        .alias span $fb

in_span:
        ldy #0
        sec
        sbc (span),y    ; A - left: C clear when A < left
        bcc outside
        iny
        cmp (span),y    ; C set when A - left >= width
        rts
outside:
        sec
        rts
