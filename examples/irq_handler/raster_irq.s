; raster_irq: a raster interrupt handler hooked into the KERNAL's IRQ chain (the $0314 vector). It
; acknowledges the VIC-II's raster interrupt, counts frames, sets the border colour of this frame from
; an eight-entry table and leaves through the KERNAL's $EA31 (keyboard scan, then the registers back
; and RTI), as a hooked handler does on a real C64.
;
; In:  frame = the frame counter; the handler is entered as the CPU enters an IRQ handler.
; Out: frame + 1 (mod 256), $D019 written with 1 (the raster source acknowledged), $D020 written with
;      colours[(frame + 1) & 7]; it ends with JMP $EA31.
        .org $c000
        .alias vic_irq  $d019
        .alias border   $d020
        .alias kernal_irq_exit $ea31

irq:    lda #1
        sta vic_irq         ; acknowledge the raster interrupt
        inc frame
        lda frame
        and #7
        tax
        lda colours,x
        sta border
        jmp kernal_irq_exit

frame:  .byte 0
colours: .byte 0, 11, 12, 15, 1, 15, 12, 11
