"""Generate asm/aabb_sprite.s: the sprite-hitbox overlap test whose program counter holds the high byte.

Run `python asm/generate/aabb_sprite.py` to rewrite asm/aabb_sprite.s, `--check` to exit 1 when the
file on disk differs from what this script generates. The output is deterministic (no set or dict
order, no randomness), so the file in the repository is exactly this script's output.

Method
------
Per axis the routine sums `d = (p2 + o2) - (p1 + o1)` in A one byte at a time (x adds
`256 * (x2h - x1h)`; sprite 2's x2h arrives in the carry, sprite 1's x1h in X). Nothing holds the
high byte of `d`: every carry, borrow and x1h test is a branch, and each branch leads to a block
that knows what the high byte is. A block is one state of a small machine:

    (axis, terms left, high part K, offset, carry C, extra instructions still allowed)

with the true value `d = 256 * K + A - offset` (A the accumulator) and C the carry flag the next
instruction will see. `ADC t` moves the state to (K, offset + C, C=0) or, on carry out,
(K + 1, offset + C, C=1); `SBC t` to (K, offset - (1 - C), C=1) or, on borrow, (K - 1, ..., C=0):
the +-1 that a carry left in A is not reset with CLC/SEC but carried along in `offset` (the program
counter knows it). `DEX` on x1h moves K down by one when x1h was 1. The few extra instructions a
block may use (SEC/CLC to flip the carry, `ADC #0` / `SBC #0` to fold the offset back into A) are
limited to two per axis, which keeps the state space finite. When no term is left, only K = 0
(0 <= d < 256: overlap iff d < size of box 1) or K = -1 (overlap iff d > -size of box 2) can
overlap, and the end block does the one compare its (K, offset, C) needs; a state whose range of d
cannot meet -254..254 returns "no overlap" at once.

Dynamic program: `worst(state)` is the fewest cycles, on the worst input, from a state to the
return, minimised over the next action (which term to add or subtract next, a carry flip, an
offset fold, or the end compare); x's end blocks continue into y's start (`TYA`) with the carry
they leave. A branch costs 2 cycles falling through and 3 taken (page crossings are not counted),
and each branch lets the costlier outcome fall through, so a block costs its instruction plus
`min(max(2 + a, 3 + b), max(2 + b, 3 + a))`. Ties go to the first action tried: terms in the fixed
orders X_TERMS and Y_TERMS, then a carry flip, then an offset fold, then the end compare.

Block emission: from the entry branch on x2h the blocks are written depth first; the fall-through
outcome of each branch is written right after it (a second arrival at a state gets a fresh copy of
its block, or a JMP when the path has 3 cycles to spare), the taken outcome goes on a stack and is
written later or branches to the copy already written. The x2h = 1 half is written last, after
y's blocks, with its own `_miss2` / `_out2` returns, so most of its branches stay short.

Branch range: a 6502 branch reaches -128..+127 bytes. The assembler is run with branch extension
off (retro.assembler), so out-of-range branches are fixed here: the first one in the file becomes
`bXX _tN / JMP target / _tN:` with the opposite condition, and the layout is measured again until
none is left (each fix only lengthens the code, so this ends). The blocks' `worst` comments are
the search's counts, without these detours.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import NamedTuple

from retro.fileio import read_text, write_atomic
from retro.paths import ASM_DIR

OUTPUT = ASM_DIR / "aabb_sprite.s"

# ---- the search --------------------------------------------------------------------------------


class Term(NamedTuple):
    kind: str  # "add" (ADC), "sub" (SBC) or "hbit" (DEX on x1h, a 256 to subtract)
    name: str  # the zero-page alias (or register) that holds it


# The order ties are broken in. It is a choice, not a derivation: with it the search lays out the
# 380-byte file that `retro check aabb_sprite --exhaustive` passed; other orders give the same
# worst case with other layouts.
X_TERMS: tuple[Term, ...] = (Term("hbit", "x1h"), Term("sub", "ox1"), Term("sub", "x1"), Term("add", "ox2"))
Y_TERMS: tuple[Term, ...] = (Term("sub", "oy1"), Term("add", "oy2"), Term("sub", "y1"))

EXTRA_INSTRUCTIONS = 2  # carry flips and offset folds allowed per axis; bounds the state space
MAX_OFFSET = 3  # |offset| and |K| beyond these are never worth reaching (search bound)
MAX_HIGH = 4
OVERLAP_SPAN = 254  # sizes 1..255: overlap needs -254 <= d <= 254

# 6502 cycle counts (MOS datasheet): zero-page ADC/SBC/CMP 3, immediate and implied 2, RTS 6,
# branch 2 not taken / 3 taken.
ZP_OP = 3
IMPLIED = 2
RTS = 6
BRANCH_FALL = 2
BRANCH_TAKEN = 3
JMP = 3
INF = 10**9


@dataclass(frozen=True)
class State:
    axis: str  # "x" or "y"
    left: tuple[Term, ...]  # terms still to sum, in tie-break order
    high: int  # K: d = 256 * K + A - offset
    offset: int
    carry: int  # the carry flag the next instruction sees
    extra: int  # extra instructions still allowed on this axis


class Action(NamedTuple):
    kind: str  # "term", "flip", "inc", "dec", "miss" or an end compare ("x_low", "x_minus1", ...)
    term: Term | None = None


def _branch(a: int, b: int) -> int:
    """Cycles of a two-way branch whose outcomes then cost a and b: the dearer one falls through."""
    return min(max(BRANCH_FALL + a, BRANCH_TAKEN + b), max(BRANCH_FALL + b, BRANCH_TAKEN + a))


def _without(terms: tuple[Term, ...], term: Term) -> tuple[Term, ...]:
    return tuple(t for t in terms if t != term)


def _cannot_overlap(s: State) -> bool:
    """True when every value the remaining terms can give d lies outside -254..254."""
    adds = sum(1 for t in s.left if t.kind == "add")
    subs = len(s.left) - adds
    # each term moves K and the offset by at most one; while terms are left, offset folds may move
    # the offset by up to EXTRA_INSTRUCTIONS more
    folds = EXTRA_INSTRUCTIONS if s.left else 0
    lo = 256 * (s.high - subs) - (s.offset + adds + folds)
    hi = 256 * (s.high + adds) + 255 - (s.offset - subs - folds)
    return hi < -OVERLAP_SPAN or lo > OVERLAP_SPAN


def _miss_cost(carry: int) -> int:
    return RTS if carry == 0 else IMPLIED + RTS  # a set carry needs a CLC before the RTS


def outcomes(s: State, action: Action) -> tuple[State, State]:
    """The two states after a branching action: (a, b), where a is the 'carry clear'/'x1h = 0' side
    for ADC and x1h, and the 'carry set' (no borrow) side for SBC."""
    def at(left: tuple[Term, ...], high: int, offset: int, carry: int, extra: int) -> State:
        return State(s.axis, left, high, offset, carry, extra)

    if action.kind == "term":
        assert action.term is not None
        left = _without(s.left, action.term)
        if action.term.kind == "add":
            return at(left, s.high, s.offset + s.carry, 0, s.extra), at(left, s.high + 1, s.offset + s.carry, 1, s.extra)
        if action.term.kind == "sub":
            borrow_in = 1 - s.carry
            return (at(left, s.high, s.offset - borrow_in, 1, s.extra),
                    at(left, s.high - 1, s.offset - borrow_in, 0, s.extra))
        return at(left, s.high, s.offset, s.carry, s.extra), at(left, s.high - 1, s.offset, s.carry, s.extra)
    if action.kind == "inc":  # ADC #0 with C=1
        return (at(s.left, s.high, s.offset + 1, 0, s.extra - 1),
                at(s.left, s.high + 1, s.offset + 1, 1, s.extra - 1))
    if action.kind == "dec":  # SBC #0 with C=0
        return (at(s.left, s.high, s.offset - 1, 1, s.extra - 1),
                at(s.left, s.high - 1, s.offset - 1, 0, s.extra - 1))
    raise ValueError(f"{action.kind} does not branch")


def _flipped(s: State) -> State:
    return State(s.axis, s.left, s.high, s.offset, 1 - s.carry, s.extra - 1)


def start_state(axis: str, high: int, carry: int) -> State:
    return State(axis, X_TERMS if axis == "x" else Y_TERMS, high, 0, carry, EXTRA_INSTRUCTIONS)


def y_entry_cost(carry: int) -> int:
    """Worst cycles from `_ystart0`/`_ystart1` (TYA, then y's sum) to the return."""
    return IMPLIED + worst(start_state("y", 0, carry))[0]


@cache
def worst(s: State) -> tuple[int, Action | None]:
    """Fewest worst-case cycles from state s to the return, and the action that achieves it."""
    if abs(s.offset) > MAX_OFFSET or abs(s.high) > MAX_HIGH:
        return INF, None
    if _cannot_overlap(s):
        return _miss_cost(s.carry), Action("miss")
    best: tuple[int, Action | None] = (INF, None)

    def consider(cycles: int, action: Action) -> None:
        nonlocal best
        if cycles < best[0]:  # strict: the first action tried wins a tie
            best = (cycles, action)

    for term in s.left:
        action = Action("term", term)
        a, b = outcomes(s, action)
        cost = IMPLIED if term.kind == "hbit" else ZP_OP
        consider(cost + _branch(worst(a)[0], worst(b)[0]), action)
    if s.extra > 0:
        consider(IMPLIED + worst(_flipped(s))[0], Action("flip"))
        fold = Action("inc" if s.carry == 1 else "dec")
        a, b = outcomes(s, fold)
        consider(IMPLIED + _branch(worst(a)[0], worst(b)[0]), fold)
    if not s.left:
        for cycles, action in _end_compares(s):
            consider(cycles, action)
    return best


def _end_compares(s: State) -> list[tuple[int, Action]]:
    """The end blocks that fit state s (no terms left), with their worst cycles."""
    ends = []
    low = (s.high, s.offset) == (0, 0)  # d = A: overlap iff d < size of box 1
    minus_one = (s.high, s.offset) == (-1, -1)  # d = A - 255: overlap iff A + size of box 2 >= 256
    minus_exact = (s.high, s.offset) == (-1, 0) and s.carry == 0  # d = A - 256: A + size > 256
    if s.axis == "x":
        if low:  # CMP w1 / BCC _ystart0 / CLC / RTS
            ends.append((ZP_OP + max(BRANCH_FALL + _miss_cost(1), BRANCH_TAKEN + y_entry_cost(0)), Action("x_low")))
        if minus_one and s.carry == 0:  # ADC w2 / BCS _ystart1 / RTS
            ends.append((ZP_OP + max(BRANCH_FALL + RTS, BRANCH_TAKEN + y_entry_cost(1)), Action("x_minus1")))
        if minus_exact:  # ADC w2 / BCC _out / BNE _ystart1 / CLC / RTS
            ends.append((ZP_OP + max(BRANCH_TAKEN + RTS,
                                     BRANCH_FALL + max(BRANCH_FALL + _miss_cost(1), BRANCH_TAKEN + y_entry_cost(1))),
                         Action("x_minus0")))
    else:
        clc = IMPLIED * s.carry
        if low:  # (CLC) EOR #$FF / ADC h1 / RTS: carry = h1 > d
            ends.append((clc + IMPLIED + ZP_OP + RTS, Action("y_low")))
        if minus_one:  # (CLC) ADC h2 / RTS
            ends.append((clc + ZP_OP + RTS, Action("y_minus1")))
        if minus_exact:  # ADC h2 / BEQ _miss / RTS
            ends.append((ZP_OP + max(BRANCH_FALL + RTS, BRANCH_TAKEN + _miss_cost(1)), Action("y_minus0")))
    return ends


def routine_worst() -> int:
    """Worst cycles of the whole routine as the search counts them (the entry branch on x2h first)."""
    return _branch(worst(start_state("x", 0, 0))[0], worst(start_state("x", 1, 1))[0])


# ---- block emission ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Line:
    """One source line: a label, an instruction, or both (`_miss:  clc`)."""
    label: str | None = None
    mnemonic: str | None = None
    operand: str | None = None
    comment: str | None = None

    def render(self) -> str:
        instruction = self.mnemonic + (f" {self.operand}" if self.operand else "") if self.mnemonic else ""
        if self.label and instruction:
            return f"{self.label + ':':<8}{instruction}"
        if self.label:
            return f"{self.label}:" + (f"                      ; {self.comment}" if self.comment else "")
        return f"        {instruction:<24}; {self.comment}" if self.comment else f"        {instruction}"

    @property
    def size(self) -> int:
        """Bytes: every operand in this routine is a zero-page alias, an immediate or a branch target."""
        if not self.mnemonic:
            return 0
        if self.mnemonic == "jmp":
            return 3
        return 2 if self.operand else 1


def _op(mnemonic: str, operand: str | None = None, comment: str | None = None) -> Line:
    return Line(mnemonic=mnemonic, operand=operand, comment=comment)


# Per branching action: the instruction, its cycles, and the branch taken when outcome a / b occurs.
_BRANCHING: dict[str, Callable[[Action], tuple[Line, int, str, str]]] = {
    "add": lambda a: (_op("adc", a.term.name), ZP_OP, "bcc", "bcs"),
    "sub": lambda a: (_op("sbc", a.term.name), ZP_OP, "bcs", "bcc"),
    "hbit": lambda a: (_op("dex", comment="x1h: 1 -> Z"), IMPLIED, "bne", "beq"),
    "inc": lambda a: (_op("adc", "#0"), IMPLIED, "bcc", "bcs"),
    "dec": lambda a: (_op("sbc", "#0"), IMPLIED, "bcs", "bcc"),
}
_CLC_FIRST = ("y_low", "y_minus1")  # end blocks whose ADC needs the carry clear

_END_BLOCKS: dict[str, list[Line]] = {
    "x_low": [_op("cmp", "w1"), _op("bcc", "_ystart0"), _op("clc"), _op("rts")],
    "x_minus1": [_op("adc", "w2"), _op("bcs", "_ystart1"), _op("rts")],
    "x_minus0": [_op("adc", "w2"), _op("bcc", "_out"), _op("bne", "_ystart1"), _op("clc"), _op("rts")],
    "y_low": [_op("eor", "#$ff"), _op("adc", "h1"), _op("rts")],
    "y_minus1": [_op("adc", "h2"), _op("rts")],
    "y_minus0": [_op("adc", "h2"), _op("beq", "_miss"), _op("rts")],
}


class _Emitter:
    """Writes the blocks in the order described in the module docstring."""

    def __init__(self) -> None:
        self.lines: list[Line] = []
        self.names: dict[State, str] = {}
        self.emitted: set[State] = set()  # membership only: never iterated, so order stays fixed
        self.pending: list[tuple[State, int]] = []  # taken outcomes still to write, with cycle budget
        self.copies = 0
        self.return_suffix = ""  # "2" while writing the x2h = 1 half, which has its own returns

    def label(self, s: State) -> str:
        if s not in self.names:
            self.names[s] = f"_{s.axis}{len(self.names)}"
        return self.names[s]

    def target(self, s: State) -> str:
        if worst(s)[1] == Action("miss"):
            return ("_miss" if s.carry == 1 else "_out") + self.return_suffix
        return self.label(s)

    def branch(self, if_a: str, if_b: str, a: State, b: State, budget: int) -> None:
        """The branch after an instruction: the outcome the search found dearer falls through."""
        wa, wb = worst(a)[0], worst(b)[0]
        if max(BRANCH_FALL + wa, BRANCH_TAKEN + wb) <= max(BRANCH_FALL + wb, BRANCH_TAKEN + wa):
            fall, taken, mnemonic = a, b, if_b
        else:
            fall, taken, mnemonic = b, a, if_a
        self.lines.append(_op(mnemonic, self.target(taken)))
        if worst(taken)[1] != Action("miss"):
            self.pending.append((taken, budget - BRANCH_TAKEN))
        self.place(fall, budget - BRANCH_FALL)

    def place(self, s: State, budget: int) -> None:
        cycles, action = worst(s)
        assert action is not None, s
        if action.kind == "miss":  # only ever reached inline, as a fall-through
            if s.carry == 1:
                self.lines.append(_op("clc"))
            self.lines.append(_op("rts"))
            return
        if s in self.emitted and cycles + JMP <= budget:
            self.lines.append(_op("jmp", self.label(s), "slack: off the worst path"))
            return
        if s in self.emitted:
            self.copies += 1
            name = f"{self.label(s)}_{self.copies}"
        else:
            name = self.label(s)
        self.emitted.add(s)
        left = ",".join(sorted(t.name for t in s.left)) or "-"
        self.lines.append(Line(label=name, comment=f"{s.axis}: left {left}; high {s.high}, offset {s.offset}, "
                                                    f"C={s.carry}; worst {cycles}"))
        kind = action.term.kind if action.kind == "term" and action.term else action.kind
        if kind in _BRANCHING:
            instruction, cost, if_a, if_b = _BRANCHING[kind](action)
            self.lines.append(instruction)
            a, b = outcomes(s, action)
            self.branch(if_a, if_b, a, b, budget - cost)
        elif kind == "flip":
            self.lines.append(_op("sec" if s.carry == 0 else "clc"))
            self.place(_flipped(s), budget - IMPLIED)
        else:
            if kind in _CLC_FIRST and s.carry == 1:
                self.lines.append(_op("clc"))
            self.lines.extend(_END_BLOCKS[kind])

    def drain(self) -> None:
        while self.pending:
            s, budget = self.pending.pop()  # last in, first out: depth first
            if s not in self.emitted:
                self.place(s, budget)

    def y_start(self, carry: int) -> None:
        self.lines.append(Line(label=f"_ystart{carry}"))
        self.lines.append(_op("tya", comment="A = y2"))
        self.place(start_state("y", 0, carry), y_entry_cost(carry) - IMPLIED)

    def routine(self) -> list[Line]:
        self.lines.append(Line(label="aabb_sprite"))
        self.branch("bcc", "bcs", start_state("x", 0, 0), start_state("x", 1, 1), routine_worst())
        x2h_set_half = self.pending.pop(0)  # the entry's taken side, written last (see docstring)
        self.drain()
        self.lines += [Line("_miss", "clc"), Line("_out", "rts")]
        self.y_start(0)
        self.y_start(1)
        self.drain()
        self.pending.append(x2h_set_half)
        self.return_suffix = "2"
        self.drain()
        self.lines += [Line("_miss2", "clc"), Line("_out2", "rts")]
        return self.lines


# ---- branch range ------------------------------------------------------------------------------

_OPPOSITE = {"bcc": "bcs", "bcs": "bcc", "beq": "bne", "bne": "beq", "bmi": "bpl", "bpl": "bmi",
             "bvc": "bvs", "bvs": "bvc"}
BRANCH_REACH = range(-128, 128)  # signed 8-bit displacement from the next instruction


def _first_out_of_range(lines: list[Line]) -> int | None:
    address, where, at = 0, {}, []
    for line in lines:
        at.append(address)
        if line.label:
            where[line.label] = address
        address += line.size
    for i, line in enumerate(lines):
        if line.mnemonic in _OPPOSITE and where[line.operand] - (at[i] + 2) not in BRANCH_REACH:
            return i
    return None


def fix_branch_range(lines: list[Line]) -> tuple[list[Line], int]:
    """Replace out-of-range branches by an opposite branch around a JMP; returns (lines, detours)."""
    lines = list(lines)
    detours = 0
    while (i := _first_out_of_range(lines)) is not None:
        detours += 1
        far = lines[i]
        skip = f"_t{detours}"
        lines[i:i + 1] = [_op(_OPPOSITE[far.mnemonic], skip), _op("jmp", far.operand), Line(label=skip)]
    return lines, detours


# ---- the file ----------------------------------------------------------------------------------

# Hand-written: the calling convention and the method in words. {detours} is filled in from the
# branch-range fix; the cycle figures come from `retro check aabb_sprite` and are kept by hand.
HEADER = """\
; aabb_sprite: do two sprite hitboxes overlap? C64 sprite coordinates: 9-bit X ($D010 bit), 8-bit Y,
; each hitbox given as an offset and a size inside its sprite.
;
; In:  sprite 2's X in registers as a game holds it: A = x2 low byte, C = x2h ($D010 bit, e.g.
;      LDA $D010 / AND #bit / CMP #1), Y = y2; X = x1h (sprite 1's $D010 bit, 0 or 1).
;      Zero page: $10 x1 (low byte)  $11 y1  $12 ox1  $13 oy1  $14 w1  $15 h1   (sprite 1)
;                 $16 ox2  $17 oy2  $18 w2  $19 h2                                (sprite 2)
;      Hitbox of sprite n: pixels xn+256*xnh+oxn .. +wn-1, yn+oyn .. +hn-1 (sprite coordinates).
; Out: carry set = the hitboxes share a pixel; carry clear = they do not. A, X: undefined; Y kept.
; Edge convention (as aabb8 and retro.geometry): touching hitboxes do NOT overlap.
; Method: per axis d = (p2 + o2) - (p1 + o1) (x: with 256 * (x2h - x1h)) is summed in A one byte
;      at a time; each carry, borrow and $D010 bit is a branch, and the branches lead to copies of
;      the rest of the sum that know the high part of d and the +-1 left by a carry they did not
;      reset (the program counter holds them, so no INY/DEY, CLC or SEC is paid for them). At the
;      end only high part 0 (0 <= d < 256: overlap iff d < w1) or -1 (overlap iff d > -w2) can
;      overlap, and each copy does the one compare its state needs. The blocks are laid out by
;      asm/generate/aabb_sprite.py (a search over the orders of the terms); each block's comment
;      gives its state (terms left, high part, offset, carry) and the worst case from its first
;      instruction as that search counted it, i.e. without the {detours} `bXX _tN / jmp` detours that
;      keep branches in range (they add up to 6 cycles to some paths).
; Cost: 31-70 cycles (static 31-70, reached), no tables: the sum is 4 terms on x (3 carries and 2
;      $D010 bits decide the high part) and 4 on y (3 carries), each a read and a branch.
; Domain: every input with x1h, x2h in 0/1 and sizes >= 1 (`retro check aabb_sprite`).
        .org $c000
        .alias x1  $10
        .alias y1  $11
        .alias ox1 $12
        .alias oy1 $13
        .alias w1  $14
        .alias h1  $15
        .alias ox2 $16
        .alias oy2 $17
        .alias w2  $18
        .alias h2  $19

"""


def generate() -> str:
    """The full text of asm/aabb_sprite.s."""
    lines, detours = fix_branch_range(_Emitter().routine())
    return HEADER.format(detours=detours) + "\n".join(line.render() for line in lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help=f"exit 1 if {OUTPUT.name} differs from what would be generated; write nothing")
    args = parser.parse_args(argv)
    text = generate()
    if args.check:
        if read_text(OUTPUT, "routine source") != text:
            print(f"{OUTPUT}: differs from its generator; run python asm/generate/aabb_sprite.py", file=sys.stderr)
            return 1
        print(f"{OUTPUT}: up to date")
        return 0
    write_atomic(OUTPUT, text)
    print(f"wrote {OUTPUT} (worst case {routine_worst()} cycles as the search counts them)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
