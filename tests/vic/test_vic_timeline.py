"""The CPU's timeline on a C64: Bad Lines and sprite DMA stop it, the VIC-II's IRQ interrupts it.

Every expected figure is worked out by hand from the rules in docs/vic.md ("CPU timeline"): Bauer's
6569/6567R56A/6567R8 timing diagrams (Bad Line BA low in cycles 12-54, sprite n's s-accesses in
cycles 58+2n and 59+2n of the line before its row; 59+2n and 60+2n on the 6567R56A, and on the
6567R8 as the real machines of VICE-testprogs VICII/spritesteal show), BA low 3 cycles earlier, the
CPU stopping at its first read cycle) and the 6502's interrupt polling (penultimate cycle; a taken
branch without page crossing polls a cycle earlier; CLI/SEI/PLP act after the poll). Offsets below
count cycles from the routine's first cycle; "line L cycle c" is offset c - 1 when it starts there.
"""

from __future__ import annotations

import pytest

from retro.assembler import assemble_text
from retro.chips.vic.constants import NTSC, PAL, REGISTER_COUNT, SPRITE_BYTES, SPRITE_COUNT
from retro.chips.vic.device import VicDevice
from retro.chips.vic.model import VicState
from retro.cpu.machine import Machine
from retro.machines import build_machine
from retro.machines.c64 import build_c64, call_budget, install_kernal_irq_entry, vic_of

FULL_SPRITE = bytes([0xFF] * SPRITE_BYTES)
DEN_OFF = 0x0B  # $D011: RSEL, YSCROLL 3, display off (no Bad Lines)
DEN_ON = 0x1B  # the power-on value: Bad Lines on lines $33, $3B, ...


def vic_state(video, registers: dict[int, int], sprites: dict[int, tuple[int, int]] = {}) -> VicState:
    values = bytearray(REGISTER_COUNT)
    for offset, value in registers.items():
        values[offset] = value
    data = [bytes(SPRITE_BYTES)] * SPRITE_COUNT
    for n, (x, y) in sprites.items():
        values[2 * n], values[2 * n + 1] = x & 0xFF, y
        values[0x10] |= (x >> 8) << n
        values[0x15] |= 1 << n
        data[n] = FULL_SPRITE
    return VicState(video, bytes(values), tuple(data))


def machine_at(source: str, state: VicState, line: int, cycle: int = 1) -> tuple[Machine, VicDevice]:
    machine = build_c64(state, start_line=line, start_cycle=cycle)
    machine.load(assemble_text(source))
    return machine, vic_of(machine)


# X counts iterations until $D012 shows the next line: INX (2), LDA $D012 (4, reads in its 4th
# cycle), CMP # (2), BNE (3 taken). After LDX # (2), iteration k reads at offset 7 + 11k.
LINE_COUNTER = """
.org $c000
count:  ldx #0
loop:   inx
        lda $d012
        cmp #{next}
        bne loop
        rts
"""


def count_to_next_line(video, control1: int, line: int, sprites=()) -> tuple[int, int, int]:
    state = vic_state(video, {0x11: control1}, {n: (24 + 30 * n, line) for n in sprites})
    machine, _ = machine_at(LINE_COUNTER.format(next=line + 1), state, line)
    result = machine.call("count")
    return result.x, result.cycles, result.stolen


@pytest.mark.parametrize("video, control1, line, sprites, expected", [
    # No DMA: the first read at offset >= 63 is 7 + 11*6 = 73 (X = 7); then CMP, BNE, RTS: 73 + 11.
    (PAL, DEN_OFF, 0x33, (), (7, 84, 0)),
    # Bad Line $33: iteration 0's BNE reads its operand at offset 11 (cycle 12), when BA has just
    # gone low: it waits to offset 54 (43 cycles). Iteration 1 starts at 56 (read at 61, still
    # line $33), iteration 2 reads at 72: X = 3, 72 + 11 cycles.
    (PAL, DEN_ON, 0x33, (), (3, 83, 43)),
    # One sprite fetching in line 100 (Y = 100): BA low in cycles 55-59 (offsets 54-58). Iteration
    # 4's BNE opcode fetch at 54 waits 5 cycles; iteration 5 reads at 67: X = 6, 67 + 11.
    (PAL, DEN_OFF, 100, (0,), (6, 78, 5)),
    # Eight sprites: BA low from cycle 55 to cycle 10 of the next line (offsets 54-72); the same
    # BNE waits 19 cycles, iteration 5 reads at 81: X = 6, 81 + 11.
    (PAL, DEN_OFF, 100, range(8), (6, 92, 19)),
    # 6567R8 (65 cycles): no DMA: first read at offset >= 65 is 73 (X = 7). One sprite: s-accesses
    # in cycles 59-60, BA low 56-60 (offsets 55-59): iteration 4's BNE (54-56) stops reading its
    # operand at 55 and waits 5; iteration 5 reads at 67 >= 65: X = 6 (the 6567R56A and eight
    # sprites: tests/vic/test_sprite_dma_timing.py).
    (NTSC, DEN_OFF, 100, (), (7, 84, 0)),
    (NTSC, DEN_OFF, 100, (0,), (6, 78, 5)),
])
def test_loop_counted_to_the_next_line(video, control1, line, sprites, expected):
    assert count_to_next_line(video, control1, line, tuple(sprites)) == expected


def nops_from(line: int, cycle: int, prefix: str, count: int = 30, control1: int = DEN_ON):
    source = ".org $c000\nentry: " + prefix + "\n" + "        nop\n" * count + "        rts\n"
    machine, _ = machine_at(source, vic_state(PAL, {0x11: control1}), line, cycle)
    return machine.call("entry", trace=True)


@pytest.mark.parametrize("prefix, start_cycle, stolen", [
    # NOPs from cycle 1 of Bad Line $33: the NOP in cycles 11-12 stops in its dummy read at 12 and
    # waits to 55: 43 cycles.
    ("nop", 1, 43),
    # STA abs in cycles 9-12 writes in cycle 12 (BA low, writes go on); the next opcode fetch at 13
    # waits to 55: 42.
    ("sta $0400", 9, 42),
    # INC abs in cycles 8-13 writes in 12 and 13; the fetch at 14 waits: 41.
    ("inc $0400", 8, 41),
    # BRK-like pushes: JSR in cycles 9-14 pushes in 12 and 13 and stops reading its high byte at 14.
    ("jsr sub\n        jmp done\nsub:    rts\ndone:", 9, 41),
])
def test_bad_line_steals_40_to_43_cycles_by_instruction(prefix, start_cycle, stolen):
    result = nops_from(0x33, start_cycle, prefix)
    assert result.stolen == stolen
    assert sum(entry.stolen for entry in result.trace) == stolen
    assert result.cycles == sum(entry.cycles for entry in result.trace)


def test_no_stall_without_bad_line_or_sprites():
    result = nops_from(0x33, 1, "nop", control1=DEN_OFF)
    assert (result.stolen, result.cycles) == (0, 31 * 2 + 6)


def test_first_read_that_sees_a_collision_bit():
    # Sprites 0 and 2 at (100, 100), solid: their first common pixel is line 101, X 100, latched in
    # cycle 1 + (((100 - $194) mod $1F8) + 4) // 8 = 26 of line 101 (offset 63 + 25 = 88 from line
    # 100 cycle 1); a read at offset > 88 sees it. The loop LDA $D01E (4) / BEQ (3) reads at 3 + 7k.
    # Their DMA in line 100: BA low in cycles 55-59 (sprite 0) and 59-63 (sprite 2), one window,
    # offsets 54-62. Iteration 7's BEQ (53-55) reads its operand at 54: waits 9, ends at 65; from
    # there reads at 68, 75, 82, 89: the read at 89 (line 101 cycle 27) sees %101. Without the stall
    # it would be the read at 94.
    source = ".org $c000\npoll:   lda $d01e\n        beq poll\n        rts\n"
    machine, device = machine_at(source, vic_state(PAL, {0x11: DEN_OFF}, {0: (100, 100), 2: (100, 100)}), 100)
    result = machine.call("poll")
    assert result.a == 0b101
    assert (result.cycles, result.stolen) == (89 + 1 + 2 + 6, 9)
    budget = call_budget(machine, result)
    assert (budget.start_line, budget.start_cycle) == (100, 1)
    assert (budget.end_line, budget.end_cycle) == (101, 35)  # offset 97: line 101 cycle 35


IRQ_PROGRAM = """
.org $c000
entry:  {prefix}
{body}
        rts
handler:
        inc $c200
        lda #$ff
        sta $d019
        rti
"""


def irq_run(line: int, cycle: int, prefix: str, body: str, compare: int, p: int = 0x20):
    """Raster IRQ enabled at line `compare`; returns the trace and the handler's first cycle (line, cycle)."""
    state = vic_state(PAL, {0x11: DEN_OFF, 0x12: compare, 0x1A: 0x01})
    machine, device = machine_at(IRQ_PROGRAM.format(prefix=prefix, body=body), state, line, cycle)
    handler = machine.resolve("handler")
    machine.poke(0xFFFE, [handler & 0xFF, handler >> 8])
    start = machine.cycle
    result = machine.call("entry", p=p, trace=True)
    at = start
    entries = []
    for entry in result.trace:
        entries.append((entry.mnemonic, device.beam(at)[1:]))
        at += entry.cycles
    return result, entries


def handler_start(entries):
    names = [name for name, _ in entries]
    return entries[names.index("IRQ") + 1][1]


def test_raster_irq_latency_nop_phase():
    # CLI in cycles 1-2 of line 249, NOPs at 3, 5, ..., 63: the NOP in 249:63 / 250:1 has its last
    # cycle where the IRQ comes (line 250 cycle 1): polled in its first cycle, not seen. The next NOP
    # (250:2-3) polls at 2: taken. Sequence 4-10, the handler starts in cycle 11.
    _, entries = irq_run(249, 1, "cli", "        nop\n" * 40, 250)
    assert handler_start(entries) == (250, 11)
    # One cycle later: the NOP in 250:1-2 polls at 1: taken; the handler starts in cycle 10.
    _, entries = irq_run(249, 2, "cli", "        nop\n" * 40, 250)
    assert handler_start(entries) == (250, 10)


def test_irq_during_taken_branch_waits_one_instruction():
    # CLI 249:1-2, CLC 3-4, 29 NOPs 5-62, BCC (taken, same page) in 249:63, 250:1, 250:2. The IRQ
    # comes in the branch's second cycle; a taken branch polls only in its first: not seen. The NOP
    # at 250:3-4 polls at 3: taken, sequence 5-11, handler at 12 (10 if the branch polled as usual).
    body = "        nop\n" * 29 + "        bcc next\nnext:\n" + "        nop\n" * 10
    _, entries = irq_run(249, 1, "cli\n        clc", body, 250)
    assert handler_start(entries) == (250, 12)
    names = [name for name, _ in entries]
    assert names[names.index("IRQ") - 1] == "NOP" and names[names.index("IRQ") - 2] == "BCC"


def test_cli_takes_effect_after_the_next_instruction():
    # The compare line is the start line: the IRQ is low from the routine's first cycle. CLI polls
    # with I still set; the NOP after it polls with I clear: the IRQ follows that NOP.
    result, entries = irq_run(100, 1, "cli", "        nop\n" * 3, 100, p=0x24)
    names = [name for name, _ in entries]
    assert names[:3] == ["CLI", "NOP", "IRQ"]


def test_sei_still_lets_a_pending_irq_in():
    # I clear on entry, IRQ low: SEI polls with I still clear, so the interrupt follows SEI.
    result, entries = irq_run(100, 1, "sei", "        nop\n" * 3, 100, p=0x20)
    names = [name for name, _ in entries]
    assert names[:2] == ["SEI", "IRQ"]


def test_irq_pushes_p_without_b_and_sets_i():
    source = ".org $c000\nentry:  cli\n" + "        nop\n" * 4 + "        rts\nhandler: tsx\n        lda $0101,x\n" \
             "        sta $c300\n        lda #$ff\n        sta $d019\n        rti\n"
    state = vic_state(PAL, {0x11: DEN_OFF, 0x12: 100, 0x1A: 0x01})
    machine, _ = machine_at(source, state, 100)
    handler = machine.resolve("handler")
    machine.poke(0xFFFE, [handler & 0xFF, handler >> 8])
    result = machine.call("entry", p=0x24 | 0x01)  # I and C set
    pushed = machine.peek(0xC300)[0]
    assert pushed & 0x10 == 0 and pushed & 0x20 and pushed & 0x01 and not pushed & 0x04
    assert not result.flags["I"]  # RTI restored I clear


def test_kernal_0314_indirection_costs_29_cycles_more():
    # The KERNAL entry ($FF48: PHA, TXA, PHA, TYA, PHA, TSX, LDA $0104,X, AND #, BEQ taken,
    # JMP ($0314)) takes 3+2+3+2+3+2+4+2+3+5 = 29 cycles before the program's handler.
    source = ".org $c000\nentry:  cli\n" + "        nop\n" * 40 + "        rts\nhandler: inc $c200\n" \
             "        lda #$ff\n        sta $d019\n        jmp $ea81\n"
    state = vic_state(PAL, {0x11: DEN_OFF, 0x12: 250, 0x1A: 0x01})
    machine, device = machine_at(source, state, 249, 1)
    install_kernal_irq_entry(machine)
    handler = machine.resolve("handler")
    machine.poke(0x0314, [handler & 0xFF, handler >> 8])
    start = machine.cycle
    result = machine.call("entry", trace=True)
    at = start
    for entry in result.trace:
        if entry.address == handler:
            break
        at += entry.cycles
    assert device.beam(at)[1:] == (250, 11 + 29)
    assert machine.peek(0xC200) == [1]
    assert result.x == 0 and result.y == 0  # the KERNAL exit restored them


def test_sprite_sprite_irq():
    # $D01A bit 2: the first overlap (line 101 cycle 26 as above) pulls IRQ low; the handler reads $D01E.
    source = (".org $c000\nentry:  cli\nwait:   lda $c200\n        beq wait\n        lda $c201\n        rts\n"
              "handler: lda $d01e\n        sta $c201\n        inc $c200\n        lda #$ff\n"
              "        sta $d019\n        rti\n")
    state = vic_state(PAL, {0x11: DEN_OFF, 0x1A: 0x04}, {0: (100, 100), 1: (100, 100)})
    machine, _ = machine_at(source, state, 100)
    handler = machine.resolve("handler")
    machine.poke(0xFFFE, [handler & 0xFF, handler >> 8])
    assert machine.call("entry").a == 0b11


def test_no_vic_means_no_timed_loop():
    machine = Machine()
    machine.load(assemble_text(".org $c000\nentry: nop\n rts\n"))
    assert machine.mpu.lines is None
    assert machine.call("entry").stolen == 0


def test_readme_example_raster_irq_at_line_250_ends_before_260():
    from retro.commands.run import run as run_routine
    from retro.machines.c64 import interrupt_budgets
    from retro.paths import EXAMPLES_DIR

    report = run_routine(EXAMPLES_DIR / "raster_irq_250.s", "main",
                         scene=EXAMPLES_DIR / "raster_irq_250.toml", trace=True)
    machine = report.machine
    # By hand from the data: the player (100, 120) meets enemies 1 (90, 110), 2 (110, 130) and
    # 6 (115, 105) (|dx|, |dy| < 16); enemy 4 (100, 136) is 16 below: no. Bits 1, 2, 6 = 70.
    assert report.result.a == 70
    assert machine.peek("latch") == [0b11]  # the two balls overlap above line 250
    (budget,) = interrupt_budgets(machine, report.result)
    # The IRQ comes in cycle 1 of line 250; the instruction then running (at most LDA abs held by
    # nothing on line 250 before cycle 57) ends within 7 cycles, so the sequence starts by cycle 8.
    assert budget.start_line == 250 and 1 <= budget.start_cycle <= 8
    # Sprite 1 (Y = 232) fetches on lines 232-252: at most 5 cycles (BA low 57-61) on each of lines
    # 250-252; no Bad Line after $F7.
    assert 0 < budget.stolen <= 15
    assert budget.ends_before(260)
    call = call_budget(machine, report.result)
    assert (call.start_line, call.start_cycle) == (240, 1)
    assert call.stolen >= 43  # Bad Line $F3 (243) at least


def test_vice_collision_cycle_result_reached_through_the_stalls():
    # VICE-testprogs VICII/spritecollisions readme: real C64 and C64C show "CC@@@@@" for
    # sprite-sprite-collision-cycle: with sprites 0 and 1 holding one pixel (row 0, column 0) at
    # Y $34 (row 0 on line 53) and X = 86..92, a $D01E read in cycle 25 of line 53 returns 3, 3, 0,
    # 0, 0, 0, 0. Our own program (not theirs) gets to that read from where their stable raster IRQ
    # leaves the CPU (line 51, cycle 4; docs/vic.md), through the stalls worked out by hand:
    #   NOP x4 in 51:4-11; LDA $D01E's opcode fetch in 51:12 waits for the Bad Line to 51:55, reads
    #   in 51:58 (clearing); LDX #15 at 51:59; the DEX/BNE loop (74 cycles) loses 7 cycles when
    #   iteration 11's BNE fetch meets the sprites' BA window (52:55-61); 3 NOPs; the second
    #   LDA $D01E reads 3271 + 2 + 74 + 7 + 6 + 3 = 3363 = line 53 cycle 25.
    source = (".org $c000\nentry:  nop\n        nop\n        nop\n        nop\n        lda $d01e\n"
              "        ldx #15\nloop:   dex\n        bne loop\n        nop\n        nop\n        nop\n"
              "        lda $d01e\n        rts\n")
    one_pixel = bytes([0x80]) + bytes(SPRITE_BYTES - 1)
    for x, expected in zip(range(86, 93), (3, 3, 0, 0, 0, 0, 0)):
        registers = bytearray(REGISTER_COUNT)
        registers[0x11], registers[0x15] = DEN_ON, 0b11
        registers[0], registers[1], registers[2], registers[3] = x, 0x34, x, 0x34
        state = VicState(PAL, bytes(registers), (one_pixel, one_pixel) + (bytes(SPRITE_BYTES),) * 6)
        machine, _ = machine_at(source, state, 51, 4)
        result = machine.call("entry")
        assert result.a == expected, x
        assert result.stolen == 43 + 7
        # the second read is the LDA's last cycle, 6 (RTS) before the end
        assert machine.mpu.lines.beam(machine.cycle - 6 - 1)[1:] == (53, 25)


def test_bad_line_created_mid_line_by_a_d011_write():
    # Line $33 with YSCROLL 0: no Bad Line. Nine NOPs (cycles 1-18), LDA # (19-20), STA $D011 (21-24)
    # writes YSCROLL 3 in cycle 24: BA is low from 25 to 54, so the NOP fetched at 25 waits to 55: 30.
    result = nops_from(0x33, 1, "nop\n" * 9 + "        lda #$1b\n        sta $d011", control1=0x18)
    assert result.stolen == 30


def test_bad_line_removed_before_ba_falls():
    # Line $33 is a Bad Line with $1B; writing YSCROLL 0 in cycle 6 (LDA # 1-2, STA 3-6) removes it
    # before BA would fall in cycle 12: nothing is stolen (43 without the write, as above).
    result = nops_from(0x33, 1, "lda #$18\n        sta $d011", control1=DEN_ON)
    assert result.stolen == 0


@pytest.mark.parametrize("cpu, message", [
    ({"start_line": 312}, "x.toml: cpu.start_line: "),
    ({"start_cycle": 64}, "x.toml: cpu.start_cycle: "),
    ({"start_cycle": 0}, "x.toml: cpu.start_cycle: "),
    ({"irq_vector": "$0316"}, "x.toml: cpu.irq_vector: "),
    ({"start": 1}, "x.toml: cpu.start: unknown key"),
])
def test_scene_cpu_keys_are_checked(cpu, message):
    from retro.errors import InputError
    from retro.scenes.vic import parse

    with pytest.raises(InputError) as error:
        parse({"chip": "vic-ii", "video": "pal", "cpu": cpu}, "x.toml")
    assert str(error.value).startswith(message)
    assert "\n" not in str(error.value)


def test_scene_cpu_keys_place_the_beam_and_install_the_kernal_entry():
    from retro.scenes.vic import parse

    scene = parse({"chip": "vic-ii", "video": "ntsc", "cpu": {"start_line": 200, "start_cycle": 65,
                                                              "irq_vector": "$0314"}}, "x.toml")
    machine = build_machine(scene)
    device = vic_of(machine)
    assert device.beam(machine.cycle)[1:] == (200, 65)
    assert machine.peek(0xFFFE, 2) == [0x48, 0xFF]
    assert machine.peek(0xFF48) == [0x48]  # PHA


def test_call_at_line_places_the_routine_on_the_beam():
    from retro.errors import InputError
    from retro.machines.c64 import call_at_line
    from retro.scenes.vic import parse

    scene = parse({"chip": "vic-ii", "video": "pal", "registers": {"$d011": DEN_ON}}, "x.toml")
    program = assemble_text(".org $c000\nentry:  " + "nop\n        " * 30 + "rts\n")
    # as test_bad_line_steals...: 30 NOPs and RTS from Bad Line $33 cycle 1 lose 43 cycles
    result, budget = call_at_line(scene, program, "entry", 0x33)
    assert (result.cycles, result.stolen) == (30 * 2 + 6 + 43, 43)
    assert (budget.start_line, budget.start_cycle, budget.end_line, budget.end_cycle) == (0x33, 1, 0x34, 46)
    with pytest.raises(InputError, match="--at-line"):
        call_at_line(scene, program, "entry", 312)


def _sprite0_nops(y: int, written_y: int):
    """NOPs from cycle 1 of line $40 (no Bad Lines) after `STA $D001` of `written_y`, sprite 0 on at `y`."""
    source = (".org $c000\nentry:  lda #$%02x\n        sta $d001\n" % written_y) + "        nop\n" * 40 + "        rts\n"
    machine, _ = machine_at(source, vic_state(PAL, {0x11: DEN_OFF, 0x15: 0x01, 0x01: y}), 0x40, 1)
    return machine.call("entry")


def test_a_sprite_y_write_moves_its_dma_as_if_it_had_been_there():
    # Sprite 0's Y written to $40 in cycle 6 of line $40 makes its DMA check (cycles 55-56 on the 6569)
    # match in that line: the CPU stalls as it does for a sprite that was at Y $40 from the start. Left
    # at $F0 (a write that changes nothing) it steals nothing there [Bauer 3.8.1].
    moved, there, away = _sprite0_nops(0xF0, 0x40), _sprite0_nops(0x40, 0x40), _sprite0_nops(0xF0, 0xF0)
    assert moved.stolen == there.stolen > 0
    assert away.stolen == 0
