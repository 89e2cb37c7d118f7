"""Machine: call semantics, trace, budget, halts, main loops, devices and the clock.

Programs are hand-assembled bytes (opcode comments alongside) so these tests do not depend on the
assembler; expected cycle counts are added up by hand from the 6502 datasheet timings.
"""

from __future__ import annotations

import pytest

from retro.cpu import Machine
from retro.cpu.mpu import FLAG_D
from retro.errors import InputError, RunError

ORIGIN = 0xC000


def machine_with(code: dict[int, list[int]], variant: str = "6510") -> Machine:
    machine = Machine(variant)
    for address, data in code.items():
        machine.poke(address, data)
    return machine


COUNT_DOWN = {ORIGIN: [
    0xA9, 0x01,  # C000 LDA #$01    2
    0xA2, 0x03,  # C002 LDX #$03    2
    0xCA,        # C004 DEX         2 x3
    0xD0, 0xFD,  # C005 BNE $C004   3 + 3 + 2 (taken, taken, not taken)
    0x60,        # C007 RTS         6
]}


def test_call_counts_from_the_first_instruction_through_rts_without_the_jsr():
    result = machine_with(COUNT_DOWN).call(ORIGIN)
    assert result.cycles == 2 + 2 + 3 * 2 + (3 + 3 + 2) + 6  # 24: no 6 for the caller's JSR
    assert result.instructions == 9
    assert (result.a, result.x, result.s) == (1, 0, 0xFF)
    assert result.flags["Z"] and not result.flags["N"]


def test_nested_jsr_does_not_end_the_call():
    machine = machine_with({
        ORIGIN: [0x20, 0x10, 0xC0,  # C000 JSR $C010  6
                 0xE8,              # C003 INX        2
                 0x60],             # C004 RTS        6
        0xC010: [0xA0, 0x05,        # C010 LDY #5     2
                 0x60],             # C012 RTS        6
    })
    result = machine.call(ORIGIN)
    assert (result.cycles, result.instructions) == (6 + 2 + 6 + 2 + 6, 5)
    assert (result.x, result.y) == (1, 5)


PAGE_AND_BRANCH = {0xC0F0: [
    0xA2, 0x01,        # C0F0 LDX #1          2
    0xBD, 0xFF, 0xC0,  # C0F2 LDA $C0FF,X     4 + 1: $C100 is on the next page
    0xBD, 0x00, 0xC1,  # C0F5 LDA $C100,X     4: $C101, same page
    0xA0, 0x00,        # C0F8 LDY #0          2 (Z set)
    0xD0, 0x10,        # C0FA BNE             2: not taken
    0xF0, 0x04,        # C0FC BEQ $C102       2 + 1 taken + 1 into the next page
    0x42, 0x00,        # C0FE (skipped)
], 0xC100: [
    0x42, 0x00,        # C100 data read by the LDAs
    0xF0, 0x00,        # C102 BEQ $C104       2 + 1 taken, same page
    0x60,              # C104 RTS             6
]}


def test_trace_records_cycles_page_crossings_and_taken_branches():
    result = machine_with(PAGE_AND_BRANCH).call(0xC0F0, trace=True)
    rows = [(e.address, e.mnemonic, e.cycles, e.page_crossed, e.branch_taken) for e in result.trace]
    assert rows == [
        (0xC0F0, "LDX", 2, False, False),
        (0xC0F2, "LDA", 5, True, False),
        (0xC0F5, "LDA", 4, False, False),
        (0xC0F8, "LDY", 2, False, False),
        (0xC0FA, "BNE", 2, False, False),
        (0xC0FC, "BEQ", 4, True, True),
        (0xC102, "BEQ", 3, False, True),
        (0xC104, "RTS", 6, False, False),
    ]
    assert result.cycles == sum(row[2] for row in rows) == 28
    assert result.instructions == len(rows)


def test_traced_and_fast_runs_agree():
    fast = machine_with(PAGE_AND_BRANCH).call(0xC0F0, x=9, y=3)
    traced = machine_with(PAGE_AND_BRANCH).call(0xC0F0, x=9, y=3, trace=True)
    assert (fast.a, fast.x, fast.y, fast.p, fast.s, fast.cycles, fast.instructions) == \
        (traced.a, traced.x, traced.y, traced.p, traced.s, traced.cycles, traced.instructions)
    assert fast.trace is None


INFINITE = {ORIGIN: [0x4C, 0x00, 0xC0]}  # C000 JMP $C000 (3 cycles, forever)


def test_budget_stops_a_runaway_routine_naming_pc_and_last_instructions():
    with pytest.raises(RunError) as error:
        machine_with(INFINITE).call(ORIGIN, budget=1000)
    message = str(error.value)
    assert "1000 cycles" in message and "PC $C000" in message
    assert "after 334 instructions" in message  # the clock first reaches 1000 after ceil(1000 / 3) JMPs
    assert "$C000 JMP $C000" in message
    assert "\n" not in message


def test_budget_is_inclusive():
    assert machine_with(COUNT_DOWN).call(ORIGIN, budget=24).cycles == 24
    with pytest.raises(RunError):
        machine_with(COUNT_DOWN).call(ORIGIN, budget=23)


def test_budget_also_stops_a_traced_run():
    with pytest.raises(RunError, match="budget"):
        machine_with(INFINITE).call(ORIGIN, budget=300, trace=True)


@pytest.mark.parametrize("opcode, kind", [(0x00, "BRK"), (0x02, "JAM"), (0xF2, "JAM"), (0x8B, "ANE"), (0x9E, "SHX")])
@pytest.mark.parametrize("trace", [False, True])
def test_brk_jam_and_unstable_opcodes_stop_with_an_error(opcode, kind, trace):
    machine = machine_with({ORIGIN: [0xEA,  # C000 NOP
                                     0xE8,  # C001 INX
                                     opcode]})
    with pytest.raises(RunError) as error:
        machine.call(ORIGIN, trace=trace)
    message = str(error.value)
    assert kind in message and f"${opcode:02X}" in message and "at $C002" in message
    assert message.endswith("$C000 NOP, $C001 INX, $C002 " + machine.disassemble_at(0xC002))


def test_run_stops_at_an_address_or_after_a_number_of_cycles():
    machine = machine_with({ORIGIN: [0xE8,              # C000 INX       2
                                     0x4C, 0x00, 0xC0]})  # C001 JMP $C000 3
    start = machine.cycle
    assert machine.run(ORIGIN, cycles=50) == 20  # 10 rounds of 5 cycles
    assert machine.cycle - start == 50
    assert machine.mpu.x == 10
    assert machine.run(ORIGIN, until=0xC001) == 1
    with pytest.raises(RunError, match="budget"):
        machine.run(ORIGIN, until=0xC004, cycles=100)


def test_the_clock_keeps_running_across_calls_and_devices_see_the_bus_cycle():
    class Recorder:
        def __init__(self):
            self.events = []

        def read(self, address, cycle):
            self.events.append(("read", address, cycle))
            return 0x80

        def write(self, address, value, cycle):
            self.events.append(("write", address, value, cycle))

        def peek(self, address):
            return 0x80

    machine = machine_with({ORIGIN: [
        0xAD, 0x12, 0xD0,  # C000 LDA $D012  4: operand read in cycle 3
        0x2C, 0x12, 0xD0,  # C003 BIT $D012  4: read in cycle 3
        0x8D, 0x20, 0xD0,  # C006 STA $D020  4: write in cycle 3
        0xEE, 0x20, 0xD0,  # C009 INC $D020  6: read in 3, old value written in 4, new in 5
        0x60,              # C00C RTS        6
    ]})
    device = machine.attach(Recorder(), 0xD000, 0xD3FF)

    def accesses(start: int) -> list[tuple]:
        return [("read", 0xD012, start + 3), ("read", 0xD012, start + 4 + 3), ("write", 0xD020, 0x80, start + 8 + 3),
                ("read", 0xD020, start + 12 + 3), ("write", 0xD020, 0x80, start + 12 + 4),
                ("write", 0xD020, 0x81, start + 12 + 5)]
    machine.call(ORIGIN, trace=True)  # the clock moves on; the second call starts later
    device.events.clear()
    start = machine.cycle
    result = machine.call(ORIGIN)
    assert result.cycles == 4 + 4 + 4 + 6 + 6
    assert machine.cycle == start + result.cycles
    assert device.events == accesses(start)
    assert machine.peek(0xD012) == [0x80]
    device.events.clear()  # the recording loop (the engine agreement's) puts the same accesses on the bus
    start = machine.cycle
    cycles, *_ = machine.call_fast(ORIGIN, timed=True)
    assert cycles == machine.last_modelled == result.cycles
    assert device.events == accesses(start)


def test_the_recording_loop_reads_ram_directly_only_for_its_run():
    """Without a device on the bus run_recorded puts RAM's own accessors in place of ByteAt and WriteByte
    for the run; after it (returned or halted) the bus's are back, and a device attached later is seen."""
    machine = machine_with({ORIGIN: [0xAD, 0x12, 0xD0, 0x8D, 0x20, 0xD0, 0x60],  # LDA $D012, STA $D020, RTS
                            0xC100: [0x02]})  # JAM
    machine.poke(0xD012, 7)
    assert machine.call_fast(ORIGIN, timed=True)[1] == 7 and machine.peek(0xD020) == [7]
    assert "ByteAt" not in vars(machine.mpu) and "WriteByte" not in vars(machine.mpu)
    with pytest.raises(RunError):
        machine.call_fast(0xC100, timed=True)
    assert "ByteAt" not in vars(machine.mpu) and "WriteByte" not in vars(machine.mpu)

    class Register:
        def __init__(self):
            self.written = []

        def read(self, address, cycle):
            return 0x42

        def write(self, address, value, cycle):
            self.written.append((address, value))

        def peek(self, address):
            return 0x42

    device = machine.attach(Register(), 0xD000, 0xD3FF)
    assert machine.call_fast(ORIGIN, timed=True)[1] == 0x42 and device.written == [(0xD020, 0x42)]


def test_a_device_on_part_of_a_page_leaves_the_rest_to_ram_and_can_stall_the_cpu():
    class Dma:
        def __init__(self):
            self.writes = []

        def read(self, address, cycle):
            raise AssertionError("not read")

        def write(self, address, value, cycle):
            self.writes.append((address, value, cycle))
            machine.mpu.stall(513)

        def peek(self, address):
            return 0

    machine = machine_with({ORIGIN: [
        0xAD, 0x00, 0x40,  # C000 LDA $4000  4 (RAM)
        0x8D, 0x14, 0x40,  # C003 STA $4014  4 + 513 stalled
        0x8D, 0x15, 0x40,  # C006 STA $4015  4 (RAM)
        0x60,              # C009 RTS        6
    ]}, variant="2a03")
    dma = machine.attach(Dma(), 0x4014, 0x4014)
    machine.poke(0x4000, 7)
    start = machine.cycle
    result = machine.call(ORIGIN)
    assert result.cycles == 4 + 4 + 513 + 4 + 6
    assert dma.writes == [(0x4014, 7, start + 4 + 3)]
    assert machine.peek(0x4015) == [7]


def test_overlapping_or_out_of_range_devices_are_refused():
    machine = Machine()

    class Nothing:
        def read(self, address, cycle): return 0
        def write(self, address, value, cycle): pass
        def peek(self, address): return 0

    machine.attach(Nothing(), 0xD000, 0xD3FF)
    with pytest.raises(InputError, match="overlaps"):
        machine.attach(Nothing(), 0xD3F0, 0xD400)
    with pytest.raises(InputError, match="outside"):
        machine.attach(Nothing(), 0xFFF0, 0x10000)


def test_decimal_mode_is_bcd_on_the_6510_and_ignored_on_the_2a03():
    code = {ORIGIN: [0xF8,        # SED
                     0x18,        # CLC
                     0xA9, 0x09,  # LDA #$09
                     0x69, 0x01,  # ADC #$01
                     0x60]}       # RTS
    c64 = machine_with(code).call(ORIGIN)
    nes = machine_with(code, variant="2a03").call(ORIGIN)
    assert c64.a == 0x10  # 09 + 01 in BCD
    assert nes.a == 0x0A  # binary
    assert c64.p & FLAG_D and nes.p & FLAG_D  # the flag itself still exists on the 2A03


def test_dec_absolute_takes_six_cycles_and_lax_works():
    machine = machine_with({ORIGIN: [0xCE, 0x00, 0x02,  # DEC $0200  6 (py65 1.2.0 charged 3)
                                     0xA7, 0x10,        # LAX $10    3 (undocumented)
                                     0x60]})            # RTS        6
    machine.poke(0x0200, 0)
    machine.poke(0x10, 0x5A)
    result = machine.call(ORIGIN)
    assert result.cycles == 6 + 3 + 6
    assert machine.peek(0x0200) == [0xFF]
    assert (result.a, result.x) == (0x5A, 0x5A)


def test_reported_p_has_bit_5_set_and_no_b_flag():
    # LDA #$FF, PHA, PLP, RTS: every flag bit popped into P; B is not a register bit.
    result = machine_with({ORIGIN: [0xA9, 0xFF, 0x48, 0x28, 0x60]}).call(ORIGIN)
    assert result.p == 0xEF
    assert all(result.flags.values())


def test_call_inputs_memory_and_targets():
    machine = machine_with(COUNT_DOWN)
    machine.symbols["count_down"] = ORIGIN
    result = machine.call("count_down", memory={"$0300": [1, 2, 3], 0x0310: 9})
    assert result.cycles == 24
    assert machine.peek("$0300", 3) == [1, 2, 3] and machine.peek("0x310") == [9]
    for text in ("$C000", "0xc000", "49152", "%1100000000000000", "count_down"):
        assert machine.resolve(text) == ORIGIN
    with pytest.raises(InputError, match="unknown label 'nowhere'"):
        machine.call("nowhere")
    with pytest.raises(InputError, match="not a byte"):
        machine.call(ORIGIN, a=256)
    with pytest.raises(InputError, match="not a byte"):
        machine.poke("$0300", [1, 300])
    with pytest.raises(InputError):
        machine.resolve("$10000")
    with pytest.raises(InputError, match="unknown CPU variant"):
        Machine("z80")


def test_devices_cannot_be_mapped_on_zero_page_or_stack():
    from retro.cpu.bus import Bus
    from retro.errors import InputError

    class Quiet:
        def read(self, address, cycle):
            return 0

        def write(self, address, value, cycle):
            pass

        def peek(self, address):
            return 0

    bus = Bus()
    for start, end in ((0x0000, 0x00FF), (0x01F0, 0x0200)):
        with pytest.raises(InputError, match="pages \\$00 and \\$01"):
            bus.map(Quiet(), start, end)
    bus.map(Quiet(), 0x0200, 0x02FF)  # the first page after the stack is allowed


class _Lines:
    """A stand-in chip driving the CPU's lines: BA low in cycles [ba_from, ba_to), IRQ low from irq_at."""

    drives_cpu_lines = True
    nmi_next = 1 << 62

    def __init__(self, ba_from: int = -1, ba_to: int = -1, irq_at: int = 1 << 62):
        self.ba_from, self.ba_to, self.irq_next = ba_from, ba_to, irq_at

    def read(self, address, cycle):
        return 0

    def write(self, address, value, cycle):
        pass

    def peek(self, address):
        return 0

    def ba_wait(self, cycle):
        return self.ba_to - cycle if self.ba_from <= cycle < self.ba_to else 0

    def ba_free(self, cycle):
        return 0 if self.ba_from <= cycle < self.ba_to else (self.ba_from - cycle if cycle < self.ba_from else 1 << 62)

    def irq_low(self, cycle):
        return cycle >= self.irq_next

    def nmi_edge(self, cycle):
        return False


NOPS = {ORIGIN: [0xEA] * 6 + [0x60]}  # NOP x6 (2 each), RTS (6)


def test_ba_low_stops_the_cpu_at_its_first_read_and_is_counted_apart():
    # BA low in cycles 5..14: the NOP at 4-5 stops in its dummy read at 5 and goes on at 15.
    machine = machine_with(NOPS)
    machine.attach(_Lines(5, 15), 0xD000, 0xD0FF)
    result = machine.call(ORIGIN, trace=True)
    assert (result.cycles, result.stolen) == (6 * 2 + 6 + 10, 10)
    assert [e.stolen for e in result.trace] == [0, 0, 10, 0, 0, 0, 0]
    assert result.trace[2].cycles == 12


def test_writes_go_on_while_ba_is_low():
    # STA $0400 (8D 00 04, 4 cycles 0-3, write in 3); BA low 3..9: the write goes on, the next
    # opcode fetch (4) waits to 10: 6 cycles lost, not 7.
    machine = machine_with({ORIGIN: [0x8D, 0x00, 0x04, 0x60]})
    machine.attach(_Lines(3, 10), 0xD000, 0xD0FF)
    result = machine.call(ORIGIN)
    assert (result.cycles, result.stolen) == (4 + 6 + 6, 6)


def test_irq_sequence_takes_seven_cycles_and_uses_the_vector_in_ram():
    # IRQ low from cycle 0, I clear: the first NOP (0-1) polls at 0, the sequence runs 2-8, the
    # handler (INC $C100 = 6, RTI = 6) 9-20, then 5 NOPs and RTS: 2 + 7 + 12 + 10 + 6 = 37.
    code = dict(NOPS)
    code[0xC100] = [0xEE, 0x00, 0xC1, 0x40]  # INC $C100 (also the counter), RTI
    code[0xFFFE] = [0x00, 0xC1]
    machine = machine_with(code)
    lines = _Lines(irq_at=0)
    machine.attach(lines, 0xD000, 0xD0FF)
    lines.irq_low = lambda cycle: machine.memory[0xC100] == 0xEE  # low until the handler counts once
    result = machine.call(ORIGIN, p=0x20, trace=True)
    assert [e.mnemonic for e in result.trace[:4]] == ["NOP", "IRQ", "INC", "RTI"]
    assert result.trace[1].cycles == 7
    assert result.cycles == 37
    assert result.instructions == 9  # the interrupt sequence is not an instruction


def test_nes_nmi_at_vblank_when_2000_bit_7_is_set():
    # 2A03, PPU attached at cycle 0. LDA #$80 (0-1), STA $2000 (2-5); loop LDA $10 (3) / BEQ (3,
    # taken) from cycle 6, iteration k at 6 + 6k. Vblank: line 241 dot 1 = dot 82182, first seen by
    # CPU cycle ceil(82182 / 3) = 27394. Polls: LDA zp at s+1, the taken branch at s+3 (its first
    # cycle). s = 27390 polls at 27391 and 27393: not yet; s = 27396 polls at 27397: NMI after the
    # LDA (ends 27398), sequence 27399-27405, handler at 27406.
    from retro.machines.nes import build_nes

    code = {ORIGIN: [0xA9, 0x80, 0x8D, 0x00, 0x20, 0xA5, 0x10, 0xF0, 0xFC, 0x60],
            0xC100: [0xE6, 0x10, 0x40],  # INC $10, RTI
            0xFFFA: [0x00, 0xC1]}
    machine = build_nes()
    for address, data in code.items():
        machine.poke(address, data)
    result = machine.call(ORIGIN, trace=True)
    at = 0
    for entry in result.trace:
        if entry.address == 0xC100:
            break
        at += entry.cycles
    assert at == 27406
    assert [e.mnemonic for e in result.trace].count("NMI") == 1


def test_trace_shows_the_address_and_value_each_read_used():
    from retro.assembler import assemble_text

    program = assemble_text("""
        .org $c000
    start:
        ldx #2
        lda table,x     ; reads table+2
        cmp $10         ; reads zero page $10
        sta $11         ; a store: no value read
        rts
    table: .byte 7, 8, 9
    """)
    machine = Machine()
    machine.load(program)
    result = machine.call("start", memory={0x10: [42]}, trace=True)
    table = program.symbols["table"]
    reads = [(e.mnemonic, e.operand, e.read) for e in result.trace]
    assert reads == [("LDX", None, None), ("LDA", table + 2, 9), ("CMP", 0x10, 42), ("STA", 0x11, None),
                     ("RTS", None, None)]


def test_a_call_starts_with_interrupts_disabled():
    from retro.assembler import assemble_text

    program = assemble_text("        .org $c000\nstart:  php\n        pla\n        rts\n")
    machine = Machine()
    machine.load(program)
    # PHP pushes P with B and bit 5 set; I is set on entry (docs/specs.md): $30 | $04
    assert machine.call("start").a == 0x34
    assert machine.call("start", p=0x20).a == 0x30


def test_run_reports_cycles_without_the_6_cycle_jsr(tmp_path, capsys):
    from retro.cli import main

    source = tmp_path / "php.s"
    source.write_text("        .org $c000\nstart:  php\n        pla\n        rts\n")
    assert main(["run", str(source), "--entry", "start"]) == 0
    out = capsys.readouterr().out
    assert "13 cycles, 3 instructions" in out  # PHP 3 + PLA 4 + RTS 6
    assert "the caller's JSR, 6 cycles, is not included" in out


PENALTIES = {0xC0F0: [
    0xA2, 0x01,        # C0F0 LDX #$01       2
    0xBD, 0xFF, 0xC0,  # C0F2 LDA $C0FF,X    4 + 1 ($C100: another page)
    0xA0, 0x02,        # C0F5 LDY #$02       2
    0xB1, 0x10,        # C0F7 LDA ($10),Y    5 + 1 ($C0FF + 2)
    0xEA, 0xEA, 0xEA, 0xEA, 0xEA, 0xEA,  # C0F9 NOP x6   12
    0x88,              # C0FF DEY            2 x2
    0xD0, 0xFD,        # C100 BNE $C0FF      3 + 1 (taken into another page), then 2
    0x60,              # C102 RTS            6
], 0x10: [0xFF, 0xC0]}
PENALTIES_CYCLES = 2 + 5 + 2 + 6 + 12 + (2 + 4) + (2 + 2) + 6


def test_a_timed_call_counts_the_timing_model_as_it_runs():
    from retro.cpu.timing import model_cycles

    machine = machine_with(PENALTIES)
    record: list = []
    cycles, *_ = machine.call_fast(0xC0F0, record=record, pointer_pcs=frozenset({0xC0F7}), timed=True)
    assert cycles == machine.last_modelled == PENALTIES_CYCLES == 43
    assert model_cycles(machine.memory.__getitem__, record) == 43
    assert record[3][:5] == (0xC0F7, 1, 2, 0x24, 0xC0FF)  # (pc, x, y, P, the (zp),Y pointer) before it ran
    record = []
    machine.call_fast(0xC0F0, record=record, timed=True)  # the model reads the pointer as the call runs ...
    assert machine.last_modelled == 43
    assert model_cycles(machine.memory.__getitem__, record) == 42  # ... a record names it only in pointer_pcs
    machine.call_fast(0xC0F0)
    assert machine.last_modelled is None


def test_the_timed_calls_model_is_its_own_table_not_the_cpus_count():
    from retro.cpu.timing import StepModel

    machine = machine_with(PENALTIES)
    model = machine.step_model
    machine.step_model = StepModel(tuple(b + (op == 0xEA) for op, b in enumerate(model.bases)), model.rules, model.known)
    cycles, *_ = machine.call_fast(0xC0F0, timed=True)
    assert (cycles, machine.last_modelled) == (43, 43 + 6)


@pytest.mark.parametrize("variant, cycles", [("6510", 2 + 2 + 2 + 6), ("65c02", 2 + 3 + 2 + 6)])
def test_the_timed_model_knows_the_65c02s_decimal_cycle(variant, cycles):
    machine = machine_with({ORIGIN: [0xF8, 0x69, 0x00, 0xD8, 0x60]}, variant)  # SED, ADC #0, CLD, RTS
    assert machine.call_fast(ORIGIN, timed=True)[0] == machine.last_modelled == cycles
