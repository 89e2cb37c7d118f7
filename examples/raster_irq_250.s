; A raster interrupt at line 250 that runs a collision check (examples/raster_irq_250.toml).
;
; main installs the handler at $FFFE (the scene has no KERNAL), lets the IRQ in and returns once
; the handler has run. The handler saves A and X, reads the VIC-II's sprite-sprite latch ($D01E),
; tests the player's 16x16 box against eight enemy boxes (16x16 too) and ORs a bit per hit into
; `hits`, acknowledges the raster interrupt and returns. Does it end before line 260?
;
;   retro run examples/raster_irq_250.s --entry main --scene examples/raster_irq_250.toml
;   (README, "Raster budget", has the Python call that reports the handler's own lines.)

        .org $c000
main:   sei
        lda #<irq
        sta $fffe
        lda #>irq
        sta $ffff
        lda #0
        sta done
        cli
wait:   lda done
        beq wait
        sei
        lda hits
        rts

irq:    pha
        txa
        pha
        lda $d01e               ; which sprites the VIC-II saw touching (and clear the latch)
        sta latch
        lda #0
        sta hits
        ldx #7
next:   lda ex,x                ; |ex - px| < 16 ?  (ex - px + 15, unsigned, below 31)
        sec
        sbc px
        clc
        adc #15
        cmp #31
        bcs miss
        lda ey,x                ; |ey - py| < 16 ?
        sec
        sbc py
        clc
        adc #15
        cmp #31
        bcs miss
        lda bits,x
        ora hits
        sta hits
miss:   dex
        bpl next
        inc done
        lda #$01                ; acknowledge the raster interrupt
        sta $d019
        pla
        tax
        pla
        rti

px:     .byte 100
py:     .byte 120
ex:     .byte 10, 90, 110, 200, 100, 40, 115, 250
ey:     .byte 10, 110, 130, 120, 136, 60, 105, 250
bits:   .byte 1, 2, 4, 8, 16, 32, 64, 128
latch:  .byte 0
hits:   .byte 0
done:   .byte 0
