; Broad phases for N objects (0..64), as a 6502 game runs them before its pair tests: which pairs
; of objects does the narrow test (aabb_edges, circle_r, ...) get called on?
;
; Each candidate pair is handed to `narrow` by JSR with the two object numbers in zero page
; `pair_a` and `pair_b`. Here `narrow` counts the pairs (the 16-bit `count`), so `retro check`
; can compare the pairs with a Python reference; the per-frame study (retro chart --per-frame)
; patches `narrow` to a bare RTS and measures the driver alone: its loops, its JSR and the RTS
; it returns through. The narrow test's own cycles are the test routine's (measured apart).
; X, Y and A are not expected to survive `narrow` (every test routine uses them).
;
; pairs_all: brute force, every pair (a, b) with a < b: n(n-1)/2 calls.
;   In: zero page `n`. Out: `count`.
;
; sweep_x: sort and sweep along X. First an insertion sort of the object numbers in `order` by
;   their left edge (stable: an object moves past strictly greater edges only; a game keeps
;   `order` from the previous frame, so it is nearly sorted and the sort is cheap), then for each
;   object a in that order every later object b whose left edge is left of a's right edge
;   (x_b < x_a + w_a): exactly the pairs whose X intervals [x, x + w) overlap.
;   In: zero page `n`, `order` (the first n bytes: the object numbers, e.g. last frame's order);
;       tables `obj_x` (left edges) and `obj_w` (widths) at $c400 and $c440.
;   Out: `order` sorted, `count`.
;   Domain: w >= 1 and x + w <= 255 for every object (the right edge fits a byte).
;
; Cost with the bare RTS: pairs_all 15 + 26n + 28 per pair (n >= 1; 41 for n = 0). sweep_x, objects
; already in order with no pair: 65 + 100(n - 1) (n >= 1); + 44 per pair (13 less when the pair's
; second object is the last one); + 19 per place an object moves in the sort. Measured on generated
; layouts by retro chart --per-frame (docs/study.md, "Cost per frame"); tests/study/test_per_frame.py
; derives these from the instructions.
        .org $c000
        .alias n      $02
        .alias pair_a $03
        .alias pair_b $04
        .alias count  $05       ; and $06
        .alias item   $07
        .alias pos    $08
        .alias right  $09
        .alias order  $80       ; $80-$bf: the object numbers in X order
        .alias obj_x  $c400
        .alias obj_w  $c440

pairs_all:
        lda #0
        sta count
        sta count+1
        ldx #0
_a:     stx pair_a
        txa
        tay
_b:     iny
        cpy n
        bcs _a_done
        sty pair_b
        jsr narrow
        ldy pair_b
        jmp _b
_a_done:
        ldx pair_a
        inx
        cpx n
        bcc _a
        rts

sweep_x:
        lda #0
        sta count
        sta count+1
        ldy #1                  ; insertion sort: order[0..y-1] is sorted
_next:  cpy n
        bcs _sorted
        sty pos
        ldx order,y
        stx item
        lda obj_x,x             ; A = the key, kept through the shifts
_shift: ldx order-1,y
        cmp obj_x,x             ; C = key >= the left neighbour's edge: in place
        bcs _place
        stx order,y             ; move the neighbour right
        dey
        bne _shift
_place: ldx item
        stx order,y
        ldy pos
        iny
        bne _next               ; always (y <= 64)
_sorted:
        ldy #0
_sa:     sty pos                 ; the sweep: a at position pos
        ldx order,y
        stx pair_a
        lda obj_x,x
        clc
        adc obj_w,x
        sta right               ; a's right edge (past its last column)
_sb:     iny
        cpy n
        bcs _sa_done
        ldx order,y
        lda obj_x,x
        cmp right               ; C = b starts at or past a's end: so does every later b
        bcs _sa_done
        stx pair_b
        sty item
        jsr narrow
        ldy item
        jmp _sb
_sa_done:
        ldy pos
        iny
        cpy n
        bcc _sa
        rts

narrow: inc count               ; the pair test's place: here, count the pairs
        bne _done
        inc count+1
_done:  rts
