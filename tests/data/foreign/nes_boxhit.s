; A tiny NROM-128 cartridge holding boxhit: the carry is set when box A and box B overlap (touching
; is no overlap). Box A in zero page at boxa_x, boxa_y, boxa_w, boxa_h, box B in RAM at boxb_x ... boxb_h.
.exportzp boxa_x, boxa_y, boxa_w, boxa_h  ; exported so ld65 -Ln lists them (it leaves plain equates out)
.export boxb_x, boxb_y, boxb_w, boxb_h
boxa_x = $fb
boxa_y = $fc
boxa_w = $fd
boxa_h = $fe
boxb_x = $0300
boxb_y = $0301
boxb_w = $0302
boxb_h = $0303

.segment "HEADER"
        .byte "NES", $1a
        .byte 1                 ; 1 x 16 KiB PRG ROM
        .byte 1                 ; 1 x 8 KiB CHR ROM
        .byte $00, $00          ; mapper 0 (NROM), horizontal mirroring

.segment "CODE"
boxhit:
        lda boxb_x
        clc
        adc boxb_w
        cmp boxa_x
        beq miss
        bcc miss
        lda boxa_x
        clc
        adc boxa_w
        cmp boxb_x
        beq miss
        bcc miss
        lda boxb_y
        clc
        adc boxb_h
        cmp boxa_y
        beq miss
        bcc miss
        lda boxa_y
        clc
        adc boxa_h
        cmp boxb_y
        beq miss
        bcc miss
        sec
        rts
miss:
        clc
        rts

start:
        sei
        cld
        ldx #$ff
        txs
forever:
        jmp forever

on_nmi:
on_irq:
        rti

.segment "VECTORS"
        .word on_nmi, start, on_irq

.segment "CHARS"
