"""FALLBACK 6502 routines for the study, used only while issue 5's routines (asm/aabb8 ... pixel,
retro/routines.py) are not in the tree. Straightforward versions, not tuned: their cycle figures are
labelled "fallback" in every table. The source is generated here (with its square table) and
assembled with retro.assembler.assemble_text; nothing is written to asm/.

Calling conventions (zero page inputs, C = 1 on a hit, C = 0 otherwise; JSR not counted):
- sf_aabb8: boxes (ax, ay, aw, ah) and (bx, by, bw, bh), 8-bit, half-open: hit when
  ax < bx + bw and bx < ax + aw and the same in y. Valid while every x + w and y + h is <= 255.
- sf_circle: centres (c1x, c1y), (c2x, c2y) and rsum = r1 + r2, all 8-bit: hit when
  dx^2 + dy^2 < rsum^2 (tangent circles do not collide), exact for every 8-bit input
  (the 17-bit sum is caught by the carry).
- sf_tile_box: box pixels x0..x1, y0..y1 (inclusive, 8-bit) against a 32-column map of property
  bytes at MAP (one byte per 8x8 cell, row-major): hit when any cell the box touches is non-zero.
- sf_pixel: sprite rows (3 bytes x 21, the VIC-II layout) at (pa) and (pb), b at signed offset
  (ddx, ddy) from a, |ddx| <= 23, |ddy| <= 20: hit when some bit is set in both; the routine swaps
  a and b when ddx < 0, then ANDs each overlapping row of a with b's row shifted right by ddx,
  stopping at the first non-zero AND.
"""

from __future__ import annotations

from functools import lru_cache

MAP = 0x2000
MAP_COLUMNS = 32
SPRITE_A = 0x3000
SPRITE_B = 0x3040

_SOURCE = """
; FALLBACK routines of the speed/accuracy study (retro/analysis/study/fallback_asm.py).
.alias ax $10
.alias ay $11
.alias aw $12
.alias ah $13
.alias bx $14
.alias by $15
.alias bw $16
.alias bh $17
.alias c1x $10
.alias c1y $11
.alias c2x $12
.alias c2y $13
.alias rsum $14
.alias x0 $10
.alias y0 $11
.alias x1 $12
.alias y1 $13
.alias pa $20
.alias pb $22
.alias ddx $24
.alias ddy $25
.alias t $26
.alias t2 $27
.alias aoff $28
.alias boff $29
.alias count $2a
.alias bits $2b
.alias r0 $2c
.alias r1 $2d
.alias r2 $2e
.alias ptr $30
.alias col0 $32
.alias col1 $33
.alias rows $34
.org $c000

sf_aabb8:
        lda bx
        clc
        adc bw
        clc
        sbc ax          ; C = 1 when bx + bw - 1 >= ax, i.e. ax < bx + bw
        bcc aabb_miss
        lda ax
        clc
        adc aw
        clc
        sbc bx
        bcc aabb_miss
        lda by
        clc
        adc bh
        clc
        sbc ay
        bcc aabb_miss
        lda ay
        clc
        adc ah
        clc
        sbc by
aabb_miss:
        rts             ; C is the answer on every path

sf_circle:
        lda c1x
        sec
        sbc c2x
        bcs +
        eor #$ff
        adc #1          ; C = 0 here: |dx| = -(c1x - c2x)
*       tax
        lda c1y
        sec
        sbc c2y
        bcs +
        eor #$ff
        adc #1
*       tay
        clc
        lda sq_lo,x
        adc sq_lo,y
        sta t
        lda sq_hi,x
        adc sq_hi,y
        bcs circle_miss  ; dx^2 + dy^2 >= 65536 > rsum^2
        sta t2
        ldx rsum
        lda t
        cmp sq_lo,x
        lda t2
        sbc sq_hi,x      ; C = 1 when d^2 >= rsum^2
        bcs circle_miss
        sec
        rts
circle_miss:
        clc
        rts

sf_tile_box:
        lda x0
        lsr
        lsr
        lsr
        sta col0
        lda x1
        lsr
        lsr
        lsr
        sta col1
        lda y1
        lsr
        lsr
        lsr
        sta rows
        lda y0
        lsr
        lsr
        lsr
        sta t           ; first row
        sec
        lda rows
        sbc t
        sta rows        ; rows to scan - 1
        lda t           ; ptr = MAP + 32 * row
        lsr
        lsr
        lsr
        clc
        adc #>MAP
        sta ptr+1
        lda t
        asl
        asl
        asl
        asl
        asl
        sta ptr
tile_row:
        ldy col0
*       lda (ptr),y
        bne tile_hit
        cpy col1
        iny
        bcc -
        dec rows
        bmi tile_miss
        lda ptr
        clc
        adc #32
        sta ptr
        bcc tile_row
        inc ptr+1
        bne tile_row
tile_miss:
        clc
        rts
tile_hit:
        sec
        rts

sf_pixel:
        lda ddx
        bpl pixel_ordered
        ldx pa          ; b is left of a: swap them so that b lies at dx >= 0
        ldy pb
        stx pb
        sty pa
        ldx pa+1
        ldy pb+1
        stx pb+1
        sty pa+1
        eor #$ff
        clc
        adc #1
        sta ddx
        lda ddy
        eor #$ff
        clc
        adc #1
        sta ddy
pixel_ordered:
        lda ddy
        bmi pixel_up
        sta t           ; b starts dy rows down a: a rows dy.., b rows 0..
        asl
        adc t
        sta aoff
        lda #0
        sta boff
        lda #21
        sec
        sbc t
        sta count
        jmp pixel_shift
pixel_up:
        eor #$ff
        clc
        adc #1
        sta t           ; b starts -dy rows above a: a rows 0.., b rows -dy..
        asl
        adc t
        sta boff
        lda #0
        sta aoff
        lda #21
        sec
        sbc t
        sta count
pixel_shift:
        lda ddx
        and #7
        sta bits
        lda ddx
        lsr
        lsr
        lsr
        tax             ; whole bytes of shift: 0, 1 or 2
pixel_row:
        ldy boff
        cpx #0
        bne +
        lda (pb),y
        sta r0
        iny
        lda (pb),y
        sta r1
        iny
        lda (pb),y
        sta r2
        jmp pixel_bits
*       lda #0
        sta r0
        cpx #1
        bne +
        lda (pb),y
        sta r1
        iny
        lda (pb),y
        sta r2
        jmp pixel_bits
*       lda #0
        sta r1
        lda (pb),y
        sta r2
pixel_bits:
        ldy bits
        beq pixel_and
*       lsr r0
        ror r1
        ror r2
        dey
        bne -
pixel_and:
        ldy aoff
        lda (pa),y
        and r0
        bne pixel_hit
        iny
        lda (pa),y
        and r1
        bne pixel_hit
        iny
        lda (pa),y
        and r2
        bne pixel_hit
        iny
        sty aoff
        lda boff
        clc
        adc #3
        sta boff
        dec count
        bne pixel_row
        clc
        rts
pixel_hit:
        sec
        rts
"""


def _table(label: str, values: list[int]) -> str:
    lines = [".advance [^ + $ff] & $ff00", f"{label}:"]
    lines += ["    .byte " + ", ".join(f"${v:02x}" for v in values[i:i + 16]) for i in range(0, len(values), 16)]
    return "\n".join(lines) + "\n"


def source() -> str:
    squares = [i * i for i in range(256)]
    return (_SOURCE.replace(">MAP", f"${MAP >> 8:02x}")
            + _table("sq_lo", [s & 0xFF for s in squares]) + _table("sq_hi", [s >> 8 for s in squares]))


TABLE_BYTES = 512  # sq_lo + sq_hi
ENTRIES = ("sf_aabb8", "sf_circle", "sf_tile_box", "sf_pixel")


@lru_cache(maxsize=1)
def program():
    from retro.assembler import assemble_text

    return assemble_text(source(), name="retro/analysis/study/fallback_asm.py")


def code_bytes(entry: str) -> int:
    """Bytes from the entry to the next entry (or to the tables): the routine's own code."""
    prog = program()
    starts = sorted(prog.symbols[e] for e in ENTRIES) + [prog.symbols["sq_lo"]]
    begin = prog.symbols[entry]
    end = min(s for s in starts if s > begin)
    if entry == "sf_pixel":  # the last routine: the gap before the page-aligned table is padding
        end = _last_code_byte(prog) + 1
    return end - begin


def _last_code_byte(prog) -> int:
    rts = 0x60
    table = prog.symbols["sq_lo"] - prog.origin
    code = prog.code[:table]
    return prog.origin + max(i for i, b in enumerate(code) if b == rts)
