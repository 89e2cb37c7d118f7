"""Timing rules that tests/mutants.py found no test for, each pinned against a figure worked by hand.

Sources: [Bauer] C. Bauer, "The MOS 6567/6569 video controller (VIC-II)" 3.5 (Bad Line condition),
3.8.1 (sprite DMA), 3.12 (interrupts); 64doc and the visual6502 wiki "6502 Timing of Interrupt
Handling" (the interrupt sequence and when the CPU polls). Cycle offsets count from the routine's
first cycle; "line L cycle c" is 1-based as in Bauer's diagrams; frame time t = L * cycles + c - 1.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from retro.assembler import assemble_text
from retro.chips.vic.constants import NTSC, PAL, REGISTER_COUNT, SPRITE_BYTES, SPRITE_COUNT
from retro.chips.vic.device import VicDevice
from retro.chips.vic.dma import ba_low
from retro.chips.vic.model import VicState, sprite_rows
from retro.cpu.machine import Machine
from retro.machines.c64 import build_c64, interrupt_budgets, raster_budget, vic_of

ORIGIN = 0xC000
NEVER = 1 << 62


def registers(**values: int) -> bytes:
    """A VIC-II register file from offsets given as r11=..., r15=... (hex offsets from $D000)."""
    out = bytearray(REGISTER_COUNT)
    for name, value in values.items():
        out[int(name[1:], 16)] = value
    return bytes(out)


def low_cycles(video, regs: bytes, line: int) -> list[int]:
    """The 1-based cycles of `line` in which BA is low."""
    low = ba_low(video, regs)
    cpl = video.cycles_per_line
    return [c + 1 for c in range(cpl) if low[line * cpl + c]]


# ---- sprite DMA ------------------------------------------------------------------------------------

def test_sprite_dma_is_not_restarted_while_it_is_on():
    """[Bauer 3.8.1] DMA starts where the line's low 8 bits equal Y, unless it is still on. On the
    6567R8 (263 lines) Y = 3 matches lines 3 and 259. Started at 259 it shows rows 0-2 on lines
    260-262 and rows 3-20 on lines 0-17 of the next frame; the match at line 3 comes while it is on
    and is ignored, so nothing is shown from line 18 on and no fetch happens in lines 17-258."""
    rows = sprite_rows(NTSC, 3, False)
    expected = np.full(NTSC.lines, -1)
    expected[260:263] = [0, 1, 2]
    expected[0:18] = np.arange(3, 21)
    assert list(rows) == list(expected)
    # the BA side: sprite 0 fetches in cycles 59-60, BA low from 56 [docs/vic.md, spritesteal]
    regs = registers(r01=3, r15=1, r11=0x0B)
    assert low_cycles(NTSC, regs, 10) == [56, 57, 58, 59, 60]
    assert low_cycles(NTSC, regs, 20) == []


def test_an_expanded_sprite_fetches_on_all_42_lines():
    """[Bauer 3.8.1] With $D017 set the DMA stays on for 42 lines, one s-access triple per line: Y =
    100 fetches in lines 100-141 (rows on 101-142). PAL sprite 0: BA low in cycles 55-59."""
    plain = registers(r01=100, r15=1, r11=0x0B)
    expanded = registers(r01=100, r15=1, r17=1, r11=0x0B)
    assert low_cycles(PAL, plain, 130) == [] and low_cycles(PAL, plain, 120) == [55, 56, 57, 58, 59]
    assert low_cycles(PAL, expanded, 130) == [55, 56, 57, 58, 59]
    assert low_cycles(PAL, expanded, 141) == [55, 56, 57, 58, 59]
    assert low_cycles(PAL, expanded, 142) == []


# ---- the Bad Line condition -------------------------------------------------------------------------

BAD_LINE_BA = list(range(12, 55))  # c-accesses in 15-54, BA low 3 cycles earlier


def test_bad_lines_run_from_30_through_f7():
    """[Bauer 3.5] RASTER >= $30 and <= $F7 and RASTER & 7 == YSCROLL, with DEN set."""
    yscroll0 = registers(r11=0x10)  # DEN, YSCROLL 0
    assert low_cycles(PAL, yscroll0, 0x30) == BAD_LINE_BA
    assert low_cycles(PAL, yscroll0, 0x28) == []  # low bits 0, above the range
    assert low_cycles(PAL, yscroll0, 0xF0) == BAD_LINE_BA
    assert low_cycles(PAL, yscroll0, 0xF8) == []  # low bits 0, below the range
    yscroll7 = registers(r11=0x17)
    assert low_cycles(PAL, yscroll7, 0xF7) == BAD_LINE_BA
    assert low_cycles(PAL, yscroll7, 0x2F) == []
    assert low_cycles(PAL, yscroll7, 0x37) == BAD_LINE_BA
    assert low_cycles(PAL, registers(r11=0x07), 0x37) == []  # DEN clear: no Bad Line


# ---- the CPU against a stand-in chip ------------------------------------------------------------------

class Lines:
    """A chip driving the CPU's lines: BA low in cycles [ba_from, ba_to); IRQ low from `irq_at` until
    the handler has counted once at `counter`."""

    drives_cpu_lines = True
    nmi_next = NEVER

    def __init__(self, machine: Machine, ba_from: int = -1, ba_to: int = -1, irq_at: int = NEVER,
                 counter: int = 0xC2F0):
        self.machine, self.ba_from, self.ba_to, self.irq_next, self.counter = machine, ba_from, ba_to, irq_at, counter

    def read(self, address, cycle):
        return 0

    def write(self, address, value, cycle):
        pass

    def peek(self, address):
        return 0

    def ba_wait(self, cycle):
        return self.ba_to - cycle if self.ba_from <= cycle < self.ba_to else 0

    def ba_free(self, cycle):
        if self.ba_from <= cycle < self.ba_to:
            return 0
        return self.ba_from - cycle if cycle < self.ba_from else NEVER

    def irq_low(self, cycle):
        return cycle >= self.irq_next and self.machine.memory[self.counter] == 0

    def nmi_edge(self, cycle):
        return False


HANDLER = 0xC200  # INC $C2F0, RTI


def run_with_lines(code: dict[int, list[int]], p: int, **lines):
    """Call ORIGIN with a stand-in chip (cycles in `lines` relative to the call's first cycle)."""
    machine = Machine("6510")
    for address, data in {**code, HANDLER: [0xEE, 0xF0, 0xC2, 0x40], 0xFFFE: [0x00, 0xC2]}.items():
        machine.poke(address, data)
    start = machine.cycle
    stand_in = Lines(machine, **{k: v + start for k, v in lines.items()})
    machine.attach(stand_in, 0xD000, 0xD0FF)
    result = machine.call(ORIGIN, p=p, trace=True)
    return result, [e.mnemonic for e in result.trace]


def test_the_interrupt_sequence_pushes_while_ba_is_low():
    """64doc: the sequence reads twice (cycles 1-2), pushes PCH, PCL, P (3-5: writes, which go on
    while BA is low) and reads the vector (6-7). IRQ low from offset 0, I clear: the NOP at 0-1 polls
    at 0; the sequence takes offsets 2-8, its pushes 4-6, its vector reads 7-8."""
    nops = {ORIGIN: [0xEA] * 4 + [0x60]}
    # BA low exactly over the pushes: nothing is lost
    result, names = run_with_lines(nops, 0x20, ba_from=4, ba_to=7, irq_at=0)
    assert names[:4] == ["NOP", "IRQ", "INC", "RTI"]
    assert result.stolen == 0 and result.trace[1].cycles == 7
    # BA low 5..7: the pushes at 5 and 6 go on, the vector read at 7 waits one cycle
    result, _ = run_with_lines(nops, 0x20, ba_from=5, ba_to=8, irq_at=0)
    assert result.stolen == 1 and result.trace[1].cycles == 8


BRANCH_CROSSING = {0xC0F8: [0x18, 0xEA, 0xEA, 0xEA, 0x90, 0x02],  # CLC, NOP x3, BCC $C100 (crosses)
                   0xC100: [0xEA] * 4 + [0x60],
                   ORIGIN: [0x4C, 0xF8, 0xC0]}  # JMP $C0F8
BRANCH_SAME_PAGE = {ORIGIN: [0x18, 0xEA, 0xEA, 0xEA, 0x90, 0x00] + [0xEA] * 4 + [0x60]}  # BCC to the next byte


def test_a_branch_that_crosses_a_page_polls_in_its_penultimate_cycle():
    """visual6502 wiki: only a taken branch that stays in its page polls a cycle early. JMP 0-2, CLC
    3-4, NOPs 5-10, BCC $C0FC -> $C100 (4 cycles: taken, page crossed) 11-14 polls at 13: an IRQ low
    from 13 follows the branch."""
    _, names = run_with_lines(BRANCH_CROSSING, 0x20, irq_at=13)
    assert names[:7] == ["JMP", "CLC", "NOP", "NOP", "NOP", "BCC", "IRQ"]
    # the same-page branch (CLC 0-1, NOPs 2-7, BCC 8-10) polls in its first cycle (8): an IRQ low
    # from 9 waits for the NOP after it (11-12, polls at 11)
    _, names = run_with_lines(BRANCH_SAME_PAGE, 0x20, irq_at=9)
    assert names[:7] == ["CLC", "NOP", "NOP", "NOP", "BCC", "NOP", "IRQ"]


def test_plp_changes_i_after_the_poll():
    """64doc / visual6502 wiki: CLI, SEI and PLP change I after their poll. I set on entry, IRQ low
    from the start: LDA #$20, PHA, PLP (pulls I clear) polls with I still set; the NOP after it polls
    with I clear and the IRQ follows that NOP."""
    code = {ORIGIN: [0xA9, 0x20, 0x48, 0x28, 0xEA, 0xEA, 0x60]}
    _, names = run_with_lines(code, 0x24, irq_at=0)
    assert names[:5] == ["LDA", "PHA", "PLP", "NOP", "IRQ"]
    # PLP pulling I set with I clear before: the poll still sees I clear, the IRQ follows PLP
    code = {ORIGIN: [0xA9, 0x24, 0x48, 0x28, 0xEA, 0xEA, 0x60]}
    _, names = run_with_lines(code, 0x20, irq_at=5)  # LDA 0-1, PHA 2-4, PLP 5-8 polls at 7
    assert names[:4] == ["LDA", "PHA", "PLP", "IRQ"]


def test_rti_restores_i_before_the_poll():
    """visual6502 wiki: RTI's effect on I is immediate. I set, IRQ low from the start: push $C0/$0A and
    P = $20, RTI to $C00A with I clear: the IRQ comes right after the RTI, before the NOP there."""
    code = {ORIGIN: [0xA9, 0xC0, 0x48, 0xA9, 0x0A, 0x48, 0xA9, 0x20, 0x48, 0x40,  # C000-C009
                     0xEA, 0xEA, 0x60]}  # C00A: NOP, NOP, RTS
    _, names = run_with_lines(code, 0x24, irq_at=0)
    assert names[:9] == ["LDA", "PHA", "LDA", "PHA", "LDA", "PHA", "RTI", "IRQ", "INC"]


# ---- the VIC-II's IRQ output and raster compare ------------------------------------------------------

def vic(regs: bytes, line: int = 0, video=PAL) -> VicDevice:
    return VicDevice.at_beam(VicState(video, regs, (bytes(SPRITE_BYTES),) * SPRITE_COUNT), 0, line)


def cycle_of(line: int, cycle: int, start_line: int, video=PAL) -> int:
    """Machine cycle of (line, cycle) for a device whose beam was at (start_line, 1) at cycle 0."""
    return (line - start_line) * video.cycles_per_line + cycle - 1


def test_irq_is_low_only_while_a_latched_source_is_enabled():
    """[Bauer 3.12] IRQ is low while a bit of $D019 is set whose $D01A bit is set. Compare line 20:
    $D019 bit 0 latches in line 20 cycle 1 either way; with $D01A = 0 the line stays high."""
    at = cycle_of(25, 1, 10)
    disabled = vic(registers(r11=0x0B, r12=20), line=10)
    assert not disabled.irq_low(at)
    assert disabled.read(0xD019, at) == 0x71  # bit 0 latched, unused bits 1, bit 7 clear
    enabled = vic(registers(r11=0x0B, r12=20, r1a=1), line=10)
    assert enabled.irq_low(at) and enabled.read(0xD019, at) == 0xF1


def test_the_raster_compare_line_has_nine_bits():
    """[Bauer 3.12] The compare line is $D011 bit 7 : $D012. $D011 = $8B, $D012 = 44 compares with
    line 300, not 44: nothing in line 44; the bit latches in line 300 cycle 1."""
    device = vic(registers(r11=0x8B, r12=44, r1a=1), line=40)
    assert not device.irq_low(cycle_of(299, 63, 40))
    assert device.irq_low(cycle_of(300, 1, 40))
    device = vic(registers(r11=0x8B, r12=44, r1a=1), line=40)
    assert not device.irq_low(cycle_of(45, 1, 40))


# ---- the raster budget ---------------------------------------------------------------------------

def test_a_budget_across_the_frame_end_counts_the_frames():
    """A routine from PAL line 311 cycle 60 taking 10 cycles ends 9 cycles later: 60 + 9 = 69 = line 0
    cycle 6 of the next frame (frames = 1); one taking a frame more ends there one frame later."""
    device = vic(registers(r11=0x0B), line=311)
    start = cycle_of(311, 60, 311)
    budget = raster_budget(device, start, 10, 0)
    assert (budget.start_line, budget.start_cycle, budget.end_line, budget.end_cycle) == (311, 60, 0, 6)
    assert budget.frames == 1 and not budget.ends_before(260)
    longer = raster_budget(device, start, 10 + 312 * 63, 0)
    assert (longer.end_line, longer.end_cycle, longer.frames) == (0, 6, 2)
    within = raster_budget(device, cycle_of(311, 1, 311), 10, 0)
    assert (within.end_line, within.end_cycle, within.frames) == (311, 10, 0)


NESTED = """
.org $c000
main:   cli
wait:   lda done
        beq wait
        rts
handler:
        inc count
        lda count
        cmp #1
        bne inner
        lda #$ff
        sta $d019       ; acknowledge line 100
        lda #101
        sta $d012       ; the next IRQ: line 101
        cli
outer:  lda done
        beq outer
        rti
inner:  lda #$ff
        sta $d019
        inc done
        rti
count:  .byte 0
done:   .byte 0
"""


def test_a_nested_interrupt_is_counted_inside_the_outer_one():
    """The handler of the line-100 IRQ re-enables interrupts and waits for the one of line 101: one
    budget, from the outer sequence in line 100 (the CPU's instruction then ends within 7 cycles) to
    the outer RTI in line 101, after the inner handler (whose sequence starts in line 101)."""
    state = VicState(PAL, registers(r11=0x0B, r12=100, r1a=1), (bytes(SPRITE_BYTES),) * SPRITE_COUNT)
    machine = build_c64(state, start_line=99, start_cycle=1)
    machine.load(assemble_text(NESTED))
    handler = machine.resolve("handler")
    machine.poke(0xFFFE, [handler & 0xFF, handler >> 8])
    result = machine.call("main", trace=True)
    assert [e.mnemonic for e in result.trace].count("IRQ") == 2
    (budget,) = interrupt_budgets(machine, result)
    assert budget.start_line == 100 and 1 <= budget.start_cycle <= 8
    assert budget.end_line == 101 and budget.frames == 0 and budget.stolen == 0
    assert budget.cycles > 63  # the outer handler waited for line 101's interrupt
    assert vic_of(machine) is machine.mpu.lines


def test_interrupt_budgets_by_hand_on_a_made_up_trace():
    """Sequences open a budget, the RTI that closes the outermost one ends it: trace NOP (2), IRQ (7),
    IRQ (7, nested), RTI (6), RTI (6), RTS (6) from PAL line 50 cycle 1, 1 cycle stolen in the inner
    RTI: one budget from offset 2 (line 50 cycle 3) through offset 27 (cycle 28), 26 cycles."""
    device = vic(registers(r11=0x0B), line=50)
    machine = SimpleNamespace(mpu=SimpleNamespace(lines=device), cycle=34)
    entry = lambda mode, cycles, opcode, stolen=0: SimpleNamespace(mode=mode, cycles=cycles, opcode=opcode,
                                                                   stolen=stolen)
    trace = [entry("imp", 2, 0xEA), entry("int", 7, None), entry("int", 7, None), entry("imp", 6, 0x40, 1),
             entry("imp", 6, 0x40), entry("imp", 6, 0x60)]
    (budget,) = interrupt_budgets(machine, SimpleNamespace(trace=trace, cycles=34))
    assert (budget.start_line, budget.start_cycle, budget.end_line, budget.end_cycle) == (50, 3, 50, 28)
    assert (budget.cycles, budget.stolen, budget.frames) == (26, 1, 0)
