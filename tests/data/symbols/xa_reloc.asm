; xa -R (relocating, o65) with -L, a label left undefined for the linker
        .text
start   jsr kernal_chrout       ; given with -Lkernal_chrout, written with segment 1 (undefined)
        rts
        .data
counter .byt 0
