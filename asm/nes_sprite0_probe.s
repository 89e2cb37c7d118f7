; nes_sprite0_probe: an NROM program that sets up one sprite-zero scene, turns rendering on, waits
; an exact number of CPU cycles and reads $2002 once. Used to check the PPU model against cynes.
; The scene and the delay are bytes patched into this image by retro/nes_probe.py (see the labels
; under "patched"); the program's timing does not depend on their values, so every image of it
; reaches the final read at (fixed cycle) + (delay cycles).
; Result in RAM: `result` = the $2002 value read, `done` = $A5 once it is stored.
.alias PPUCTRL   $2000
.alias PPUMASK   $2001
.alias PPUSTATUS $2002
.alias OAMADDR   $2003
.alias PPUSCROLL $2005
.alias PPUADDR   $2006
.alias PPUDATA   $2007
.alias OAMDMA    $4014
.alias oam_page  $0200
.alias result    $0010
.alias done      $0011
.alias DONE_MARK $A5

.org $c000
; delay: JSR excluded, RTS included, with H = delay_hi, L' = delay_lo (0 means 256), t = tail 0-4:
;   H = 0: 7 + 16 + 5*L' + t cycles;  H > 0: 5 + 1256*H + 16 + 5*L' + t cycles
; (see retro/nes_probe.py delay_parameters; tests/nes/test_nes_probe.py runs it on the 6502 core).
delay:
        ldy delay_hi
        beq fine
coarse: ldx #250
inner:  dex
        bne inner
        dey
        bne coarse
fine:   ldx delay_lo
fineloop:
        dex
        bne fineloop
        jmp (tail_vector)
tail0:  nop
        rts
tail1:  bit $00
        rts
tail2:  nop
        nop
        rts
tail3:  nop
        bit $00
        rts
tail4:  nop
        nop
        nop
        rts
.checkpc $c0ff

.advance $c100
reset:
        sei
        cld
        ldx #$ff
        txs
        lda #0
        sta PPUCTRL
        sta PPUMASK
        sta done
        bit PPUSTATUS
vbl1:   bit PPUSTATUS           ; two vblanks: the PPU ignores writes for a while after power-on
        bpl vbl1
vbl2:   bit PPUSTATUS
        bpl vbl2
        ldx #0
copy_oam:
        lda scene_oam,x
        sta oam_page,x
        inx
        bne copy_oam
        lda PPUSTATUS           ; reset the $2005/$2006 toggle
        lda #$20
        sta PPUADDR
        lda #$00
        sta PPUADDR
        ldx #0
nt0a:   lda scene_ciram,x       ; CIRAM page 0 through $2000
        sta PPUDATA
        inx
        bne nt0a
nt0b:   lda scene_ciram+$100,x
        sta PPUDATA
        inx
        bne nt0b
nt0c:   lda scene_ciram+$200,x
        sta PPUDATA
        inx
        bne nt0c
nt0d:   lda scene_ciram+$300,x
        sta PPUDATA
        inx
        bne nt0d
        lda nametable1_high     ; CIRAM page 1 through $2400 (vertical) or $2800 (horizontal)
        sta PPUADDR
        lda #$00
        sta PPUADDR
nt1a:   lda scene_ciram+$400,x
        sta PPUDATA
        inx
        bne nt1a
nt1b:   lda scene_ciram+$500,x
        sta PPUDATA
        inx
        bne nt1b
nt1c:   lda scene_ciram+$600,x
        sta PPUDATA
        inx
        bne nt1c
nt1d:   lda scene_ciram+$700,x
        sta PPUDATA
        inx
        bne nt1d
        lda #$3f                ; a visible palette, for anyone who looks at the screen
        sta PPUADDR
        lda #$00
        sta PPUADDR
        ldx #0
palette:
        lda palette_data,x
        sta PPUDATA
        inx
        cpx #32
        bne palette
vbl3:   bit PPUSTATUS           ; in vblank from here: the reference point of every measurement
        bpl vbl3
        lda #0
        sta OAMADDR
        lda #>oam_page
        sta OAMDMA
        lda scroll_x            ; the toggle was reset by the last $2002 read
        sta PPUSCROLL
        lda scroll_y
        sta PPUSCROLL
        lda ctrl
        sta PPUCTRL
        lda mask
        sta PPUMASK
        jsr delay
        lda PPUSTATUS           ; the one timed read
        sta result
        lda #DONE_MARK
        sta done
forever:
        jmp forever
nmi:
irq:
        rti

palette_data:
        .byte $0f,$00,$10,$30, $0f,$00,$10,$30, $0f,$00,$10,$30, $0f,$00,$10,$30
        .byte $0f,$06,$16,$26, $0f,$06,$16,$26, $0f,$06,$16,$26, $0f,$06,$16,$26

; ---- patched --------------------------------------------------------------------------------
.advance $d000
scene_ciram:    .advance $d800          ; 2 KiB: CIRAM pages 0 and 1
scene_oam:      .advance $d900          ; 256 bytes
ctrl:           .byte 0
mask:           .byte 0
scroll_x:       .byte 0
scroll_y:       .byte 0
nametable1_high: .byte $28
delay_hi:       .byte 0
delay_lo:       .byte 1
tail_vector:    .word tail0

.advance $fffa
        .word nmi, reset, irq
