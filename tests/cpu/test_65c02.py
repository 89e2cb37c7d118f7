"""The WDC 65C02: the scalar core (MPU65C02) and the batched engine against an independent reference
stepper (ref65c02.py, written from the W65C02S data sheet with another structure), on random
single instructions of every opcode and on random instruction streams, cycles included; the opcode
table against the independent timing model; and named facts of the data sheet written out by hand."""

from __future__ import annotations

import json
import random
from pathlib import Path

import numpy as np
import pytest
from ref65c02 import Ref65C02

from retro.analysis.check import check_routine
from retro.analysis.raster import format_raster, raster_figures
from retro.cli import main
from retro.cpu.batch import BatchCpu, LaneError
from retro.cpu.machine import Machine
from retro.cpu.mpu import FLAG_D, MPU6510, CpuHalt
from retro.cpu.mpu65c02 import MPU65C02
from retro.cpu.opcodes import DOCUMENTED, OPCODE_TABLE_65C02, RESERVED, opcodes_of
from retro.cpu.flow import analyse
from retro.cpu.timing import OPCODES_65C02, instruction_cycles
from retro.errors import InputError, RunError
from retro.machines import machine_for
from retro.testing import check, spec_from_dict

REAL_FLAGS = 0xCF  # B and bit 5 exist only in pushed copies
VECTORS_PER_OPCODE = 24
HALTS = (0xCB, 0xDB)  # WAI, STP


def _image(seed: int) -> bytearray:
    return bytearray(random.Random(seed).randbytes(0x10000))


def _vectors(seed: int, opcode: int, count: int) -> list[dict]:
    rng = random.Random(seed * 1000 + opcode)
    out = []
    for _ in range(count):
        p = rng.randrange(256)
        if rng.random() < 0.5:
            p |= FLAG_D  # ADC/SBC: half the vectors in decimal mode
        # some pointers and indexes near page ends, so page crossings are common
        out.append({"pc": rng.randrange(0x0200, 0xFFF0), "a": rng.randrange(256), "x": rng.choice([rng.randrange(256), 0xFF, 1]),
                    "y": rng.choice([rng.randrange(256), 0xFF, 1]), "s": rng.randrange(256), "p": p | 0x30})
    return out


def _reference(image: bytearray, opcode: int, v: dict) -> Ref65C02:
    memory = bytearray(image)
    memory[v["pc"]] = opcode
    ref = Ref65C02(memory, v["pc"], v["a"], v["x"], v["y"], v["s"], v["p"])
    ref.step()
    return ref


def _scalar(image: bytearray, opcode: int, v: dict):
    memory = bytearray(image)  # a bytearray: a value outside 0..255 written by the core is an error
    memory[v["pc"]] = opcode
    mpu = MPU65C02(memory=memory, pc=v["pc"])
    mpu.a, mpu.x, mpu.y, mpu.sp, mpu.p = v["a"], v["x"], v["y"], v["s"], v["p"]
    mpu.step()
    return mpu


def _differences(name: str, got: dict, want: dict) -> list[str]:
    return [f"{name} {key} {got[key]} != {want[key]}" for key in want if got[key] != want[key]]


def _state(cpu_pc, a, x, y, s, p, cycles) -> dict:
    return {"pc": cpu_pc, "a": a, "x": x, "y": y, "s": s, "p": p & REAL_FLAGS, "cycles": cycles}


RUNNING = [op for op in range(256) if op not in HALTS]


@pytest.mark.parametrize("opcode", RUNNING)
def test_each_opcode_matches_the_reference_on_the_scalar_core(opcode):
    image = _image(1)
    failures = []
    for v in _vectors(1, opcode, VECTORS_PER_OPCODE):
        ref = _reference(image, opcode, v)
        mpu = _scalar(image, opcode, v)
        want = _state(ref.pc, ref.a, ref.x, ref.y, ref.s, ref.p, ref.cycles)
        got = _state(mpu.pc, mpu.a, mpu.x, mpu.y, mpu.sp, mpu.p, mpu.processorCycles)
        failures += _differences(f"${opcode:02X} at ${v['pc']:04X} {v}", got, want)
        if mpu.memory != ref.m:
            changed = np.flatnonzero(np.frombuffer(bytes(mpu.memory), np.uint8) != np.frombuffer(bytes(ref.m), np.uint8))
            failures.append(f"${opcode:02X} {v}: memory differs at {[hex(a) for a in changed[:4]]}")
    assert not failures, failures[:4]


def test_every_opcode_matches_the_reference_as_lanes_of_the_batched_engine():
    image = _image(2)
    failures = []
    for opcode in RUNNING:
        vectors = _vectors(2, opcode, VECTORS_PER_OPCODE)
        cpu = BatchCpu("65c02", bytes(image), len(vectors), stop_on_brk=False)
        lanes = np.arange(len(vectors))
        cpu.memory.write(lanes, np.array([v["pc"] for v in vectors]), opcode)
        for key, attribute in (("pc", "pc"), ("a", "a"), ("x", "x"), ("y", "y"), ("s", "sp"), ("p", "p")):
            getattr(cpu, attribute)[:] = [v[key] for v in vectors]
        cpu.step()
        base = np.frombuffer(bytes(image), np.uint8)
        for lane, v in enumerate(vectors):
            ref = _reference(image, opcode, v)
            want = _state(ref.pc, ref.a, ref.x, ref.y, ref.s, ref.p, ref.cycles)
            got = _state(*(int(getattr(cpu, name)[lane]) for name in ("pc", "a", "x", "y", "sp", "p", "cycles")))
            failures += _differences(f"${opcode:02X} {v}", got, want)
            if cpu.error[lane]:
                failures.append(f"${opcode:02X} {v}: stopped {LaneError(int(cpu.error[lane])).name}")
            expected = np.frombuffer(bytes(ref.m), np.uint8)
            changed = set(np.flatnonzero(expected != base).tolist()) | set(cpu.memory.rows)
            for address in changed:
                have = int(cpu.memory.read(np.array([lane]), np.array([address]))[0])
                if have != expected[address]:
                    failures.append(f"${opcode:02X} {v}: ${address:04X} = {have}, reference {expected[address]}")
    assert not failures, failures[:4]


@pytest.mark.parametrize("seed", range(40))
def test_random_instruction_streams_match_the_reference_step_by_step(seed):
    """Random bytes as code: every instruction's registers, flags and running cycle count agree."""
    rng = random.Random(seed)
    image = _image(100 + seed)
    pc = rng.randrange(0x0200, 0xFF00)
    ref = Ref65C02(bytearray(image), pc, 0, 0, 0, 0xFF, 0x30 | (FLAG_D if seed % 2 else 0))
    mpu = MPU65C02(memory=bytearray(image), pc=pc)
    mpu.p = ref.p
    for step in range(400):
        if mpu.memory[mpu.pc] in HALTS:
            with pytest.raises(CpuHalt):
                mpu.step()
            break
        at = mpu.pc
        mpu.step()
        ref.step()
        want = _state(ref.pc, ref.a, ref.x, ref.y, ref.s, ref.p, ref.cycles)
        got = _state(mpu.pc, mpu.a, mpu.x, mpu.y, mpu.sp, mpu.p, mpu.processorCycles)
        assert got == want, f"step {step}, ${mpu.memory[at]:02X} at ${at:04X}"
    assert mpu.memory == ref.m


@pytest.mark.parametrize("opcode, name", [(0xDB, "STP"), (0xCB, "WAI")])
def test_stp_and_wai_stop_both_engines_naming_the_opcode(opcode, name):
    machine = Machine("65c02")
    machine.poke(0xC000, [0xA9, 0x01, opcode, 0x60])
    with pytest.raises(RunError, match=f"{name}.*\\${opcode:02X}.*\\$C002"):
        machine.call(0xC000)
    cpu = BatchCpu("65c02", bytes(machine.memory), 2)
    cpu.sp[:] = 0xFD
    cpu.call(0xC000, 1000, 0xFFFF, 0xFF)
    assert cpu.error.tolist() == [LaneError.HALT] * 2 and cpu.error_pc.tolist() == [0xC002] * 2


# ---- the table, by hand from the data sheet ------------------------------------------------------------

def test_the_65c02_table_has_every_opcode_and_no_halt():
    assert sorted(OPCODE_TABLE_65C02) == list(range(256))
    assert len(opcodes_of(RESERVED, OPCODE_TABLE_65C02)) == 44  # W65C02S: 212 defined opcodes
    assert len(opcodes_of(DOCUMENTED, OPCODE_TABLE_65C02)) == 212


@pytest.mark.parametrize("opcode", range(256))
def test_each_row_equals_the_independent_timing_model(opcode):
    row, model = OPCODE_TABLE_65C02[opcode], OPCODES_65C02[opcode]
    assert (row.mnemonic, row.mode, row.cycles, row.page_penalty) == (model.mnemonic, model.mode, model.cycles,
                                                                        model.page_penalty)


@pytest.mark.parametrize("opcode, row", [
    (0x80, ("BRA", "rel", 2)), (0x6C, ("JMP", "ind", 6)), (0x7C, ("JMP", "iax", 6)), (0x1E, ("ASL", "abx", 6)),
    (0xFE, ("INC", "abx", 7)), (0xDE, ("DEC", "abx", 7)), (0x9E, ("STZ", "abx", 5)), (0x04, ("TSB", "zpg", 5)),
    (0x1C, ("TRB", "abs", 6)), (0xB2, ("LDA", "zpi", 5)), (0x92, ("STA", "zpi", 5)), (0x89, ("BIT", "imm", 2)),
    (0x3C, ("BIT", "abx", 4)), (0x1A, ("INC", "acc", 2)), (0xDA, ("PHX", "imp", 3)), (0x7A, ("PLY", "imp", 4)),
    (0x97, ("SMB1", "zpg", 5)), (0x27, ("RMB2", "zpg", 5)), (0x4F, ("BBR4", "zpr", 5)), (0xFF, ("BBS7", "zpr", 5)),
    (0xCB, ("WAI", "imp", 3)), (0xDB, ("STP", "imp", 3)), (0x5C, ("NOP", "abs", 8)), (0x44, ("NOP", "zpg", 3)),
    (0x02, ("NOP", "imm", 2)), (0x03, ("NOP", "imp", 1)), (0xFB, ("NOP", "imp", 1)), (0xDC, ("NOP", "abs", 4)),
])
def test_rows_written_out_from_the_data_sheet(opcode, row):
    have = OPCODE_TABLE_65C02[opcode]
    assert (have.mnemonic, have.mode, have.cycles) == row


def test_scalar_dispatch_takes_cycles_and_names_from_the_table():
    for opcode, row in OPCODE_TABLE_65C02.items():
        assert tuple(MPU65C02.disassemble[opcode]) == (row.mnemonic, row.mode)
        assert MPU65C02.cycletime[opcode] == row.cycles
        assert MPU65C02.extracycles[opcode] == int(row.page_penalty)


# ---- behaviour named by the data sheet, by hand ------------------------------------------------------

def _run(code: list[int], **registers):
    machine = Machine("65c02")
    machine.poke(0xC000, code + [0x60])
    return machine, machine.call(0xC000, **registers)


def test_jmp_indirect_reads_across_the_page_and_takes_6_cycles():
    machine = Machine("65c02")
    machine.poke(0x30FF, [0x34, 0x12])  # the NMOS would read the high byte from $3000
    machine.poke(0x3000, [0x99])
    machine.poke(0x1234, [0x60])
    machine.poke(0xC000, [0x6C, 0xFF, 0x30])
    result = machine.call(0xC000)
    assert result.cycles == 6 + 6 and result.instructions == 2
    nmos = Machine("6510")
    nmos.poke(0x30FF, [0x34, 0x12])
    nmos.poke(0x3000, [0x99])
    nmos.poke(0x9934, [0x60])
    nmos.poke(0xC000, [0x6C, 0xFF, 0x30])
    assert nmos.call(0xC000).cycles == 5 + 6


def test_decimal_adc_gives_valid_flags_and_takes_a_cycle_more():
    # SED; CLC; LDA #$99; ADC #$01 -> $00, C set, Z set (the NMOS leaves Z from the binary $9A: clear)
    _, result = _run([0xF8, 0x18, 0xA9, 0x99, 0x69, 0x01])
    assert (result.a, result.flags["Z"], result.flags["C"], result.flags["N"]) == (0x00, 1, 1, 0)
    assert result.cycles == 2 + 2 + 2 + 3 + 6
    _, nmos = Machine("6510"), None
    m = Machine("6510")
    m.poke(0xC000, [0xF8, 0x18, 0xA9, 0x99, 0x69, 0x01, 0x60])
    nmos = m.call(0xC000)
    assert (nmos.a, nmos.flags["Z"], nmos.cycles) == (0x00, 0, 2 + 2 + 2 + 2 + 6)


def test_brk_clears_decimal_mode():
    machine = Machine("65c02")
    machine.mpu.stop_on_brk = False
    machine.poke(0xFFFE, [0x00, 0xD0])
    machine.poke(0xD000, [0x08, 0x68, 0x85, 0x10, 0x40])  # PHP; PLA; STA $10; RTI (back past the signature byte)
    machine.poke(0xC000, [0xF8, 0x00, 0xEA, 0x60])  # SED; BRK; (signature byte); RTS
    machine.call(0xC000)
    assert machine.peek(0x10)[0] & FLAG_D == 0


def test_bbr_bbs_rmb_smb_and_bra():
    # SMB3 $10; BBS3 $10,+2; LDA #1 (skipped); RMB3 $10; BBR3 $10,+0; BRA +0
    machine, result = _run([0xB7, 0x10, 0xBF, 0x10, 0x02, 0xA9, 0x01, 0x37, 0x10, 0x3F, 0x10, 0x00, 0x80, 0x00],
                           a=7)
    assert result.a == 7 and machine.peek(0x10) == [0]
    assert result.cycles == 5 + 6 + 5 + 6 + 3 + 6


def test_store_zero_trb_tsb_and_the_zero_page_indirect_mode():
    machine = Machine("65c02")
    machine.poke(0x20, [0x00, 0x40])  # pointer to $4000
    machine.poke(0x4000, [0b1010_1010])
    # LDA #$0F; TSB $4000; LDA ($20); STZ $21 ... then TRB with A=$0A
    machine.poke(0xC000, [0xA9, 0x0F, 0x0C, 0x00, 0x40, 0xB2, 0x20, 0x64, 0x30, 0xA9, 0x0A, 0x1C, 0x00, 0x40, 0x60])
    machine.poke(0x30, [0x55])
    result = machine.call(0xC000)
    assert machine.peek(0x4000) == [0b1010_1111 & ~0x0A]
    assert machine.peek(0x30) == [0] and result.flags["Z"] == 0


# ---- choosing the CPU: retro run --cpu, scenes ---------------------------------------------------------

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "65c02_boxhit"
DATA = Path(__file__).resolve().parents[1] / "data"


def _run_cli(capsys, *args) -> tuple[int, str, str]:
    code = main(["run", str(EXAMPLE / "hit65.prg"), "--labels", str(EXAMPLE / "hit65.sym"), *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_retro_run_with_cpu_65c02_runs_the_65c02_routine(capsys):
    code, out, _ = _run_cli(capsys, "--entry", "hit65", "--cpu", "65C02", "--set", "bptr=$42,$10",
                            "--set", "box_ax=10", "--set", "box_aw=10", "--set", "box_ay=10", "--set", "box_ah=5",
                            "--set", "boxb_x=15,12,3,3", "--peek", "hit", "--json")
    assert code == 0
    record = json.loads(out)
    # the longest path: STZ 3, (zp) loads and compares 5 each, ADC (zp),Y 5, RTS 6 ...
    assert record["peek"] == {"hit": [1]} and record["cycles"] == 94


def test_retro_run_on_the_default_6510_stops_at_the_first_65c02_opcode(capsys):
    code, _, err = _run_cli(capsys, "--entry", "hit65", "--set", "bptr=$42,$10")
    assert code == 1 and "JAM (opcode $B2) at $100B" in err and err.count("\n") == 1


@pytest.mark.parametrize("args, message", [
    (("--cpu", "z80"), "--cpu: expected one of 6510, 2a03, 65c02, got 'z80'"),
    (("--cpu", "65c02", "--scene", "VIC"), "a scene for the 6510, not the 65C02"),
])
def test_retro_run_refuses_a_bad_cpu_in_one_line(capsys, args, message):
    args = tuple(str(EXAMPLE.parent / "vic_two_balls.toml") if a == "VIC" else a for a in args)
    code, _, err = _run_cli(capsys, "--entry", "hit65", *args)
    assert code == 2 and message in err and err.count("\n") == 1, err


def test_an_ines_image_is_for_the_2a03_only(capsys):
    code = main(["run", str(DATA / "foreign" / "nes_boxhit.nes"), "--entry", "$C000", "--cpu", "65c02"])
    err = capsys.readouterr().err
    assert code == 2 and "nes_boxhit.nes is a program for the 2A03" in err and err.count("\n") == 1


def test_a_bare_machine_has_no_raster_timelines_and_named_machines_keep_theirs():
    assert raster_figures("none", 10, 20, 30) == {} and format_raster("none", {}) == ""
    assert set(raster_figures("c64", 10, 20, 63)) == {"c64_pal", "c64_ntsc"}
    assert raster_figures("c64", 10, 20, 63)["c64_pal"]["max_lines"] == 1.0
    assert set(raster_figures("nes", 10, 20, 30)) == {"nes_ntsc", "nes_pal"}
    assert [machine_for(cpu) for cpu in ("6510", "2a03", "65c02")] == ["c64", "nes", "none"]


# ---- the static analysis and the timing model on 65C02 code ----------------------------------------------

BIT_BRANCH_CODE = [0x0F, 0x10, 0x05,  # $C000 BBR0 $10, $C008
                   0xA9, 0x01,        # $C003 LDA #1
                   0x80, 0x01,        # $C005 BRA $C008 (always: the BRK after it is never decoded)
                   0x00,              # $C007 BRK
                   0x60]              # $C008 RTS


def _memory(code: list[int], at: int = 0xC000) -> list[int]:
    memory = [0] * 0x10000
    memory[at:at + len(code)] = code
    return memory


def test_static_analysis_follows_bbr_both_ways_and_bra_one_way():
    bounds = analyse(_memory(BIT_BRANCH_CODE).__getitem__, 0xC000, cpu="65c02")
    assert (bounds.best, bounds.worst) == (5 + 1 + 6, 5 + 2 + 3 + 6)
    for value, cycles in ((0, 12), (1, 16)):  # bit 0 clear: BBR0 branches
        machine = Machine("65c02")
        machine.poke(0xC000, BIT_BRANCH_CODE)
        machine.poke(0x10, [value])
        assert machine.call(0xC000).cycles == cycles


def test_static_analysis_counts_the_decimal_cycle_as_possible():
    bounds = analyse(_memory([0xA9, 0x01, 0x69, 0x01, 0x60]).__getitem__, 0xC000, cpu="65c02")
    assert (bounds.best, bounds.worst) == (10, 11)
    assert analyse(_memory([0xA9, 0x01, 0x69, 0x01, 0x60]).__getitem__, 0xC000).worst == 10  # the 6510: no


@pytest.mark.parametrize("code, name", [([0x7C, 0x00, 0x20], "JMP \\(abs,X\\)"), ([0xDB], "STP"), ([0xCB], "WAI")])
def test_static_analysis_refuses_what_it_cannot_follow(code, name):
    with pytest.raises(InputError, match=f"\\$C000: {name} is not supported by the static analysis"):
        analyse(_memory(code).__getitem__, 0xC000, cpu="65c02")


def test_the_timing_model_prices_bit_branches_and_decimal_mode():
    memory = _memory([0x8F, 0x10, 0x7F], at=0xC0F0)  # BBS0 $10 to $C0F3 + $7F = $C172: another page
    read = memory.__getitem__
    assert instruction_cycles(read, 0xC0F0, 0, 0, 0x20, pointer=0x01, cpu="65c02") == 5 + 1 + 1
    assert instruction_cycles(read, 0xC0F0, 0, 0, 0x20, pointer=0x00, cpu="65c02") == 5
    memory[0xC000:0xC002] = [0x69, 0x01]  # ADC #1
    assert instruction_cycles(read, 0xC000, 0, 0, 0x28, 0, cpu="65c02") == 3
    assert instruction_cycles(read, 0xC000, 0, 0, 0x28, 0, cpu="6510") == 2
    memory[0xC000:0xC003] = [0x1E, 0x80, 0x40]  # ASL $4080,X
    assert [instruction_cycles(read, 0xC000, x, 0, 0x20, 0, cpu="65c02") for x in (0x7F, 0x80)] == [6, 7]
    assert [instruction_cycles(read, 0xC000, x, 0, 0x20, 0, cpu="6510") for x in (0x7F, 0x80)] == [7, 7]


def test_the_trace_and_errors_show_the_65c02_modes():
    machine = Machine("65c02")
    machine.poke(0xC000, [0xB2, 0x20, 0x7C, 0x00, 0x30, 0x8F, 0x10, 0xFD, 0xDB])
    assert [machine.disassemble_at(a) for a in (0xC000, 0xC002, 0xC005)] == [
        "LDA ($20)", "JMP ($3000,X)", "BBS0 $10,$C005"]
    machine.poke(0x3000, [0x05, 0xC0])
    with pytest.raises(RunError, match=r"STP \(opcode \$DB\) at \$C008; last instructions: "
                                       r"\$C000 LDA \(\$20\), \$C002 JMP \(\$3000,X\), \$C005 BBS0 \$10,\$C005, \$C008 STP"):
        machine.call(0xC000)


def test_the_trace_marks_bit_branches_taken_and_no_page_crossing_for_the_decimal_cycle():
    machine = Machine("65c02")
    machine.poke(0xC000, [0xF8, 0x69, 0x01, 0x0F, 0x10, 0x00, 0x64, 0x20, 0x60])  # SED; ADC #1; BBR0 $10,+0; STZ $20
    machine.poke(0x20, [0x77])
    trace = machine.call(0xC000, trace=True).trace
    adc, bbr, stz = trace[1], trace[2], trace[3]
    assert (adc.cycles, adc.page_crossed) == (3, False)
    assert (bbr.cycles, bbr.branch_taken, bbr.page_crossed) == (6, True, False)
    assert stz.read is None and machine.peek(0x20) == [0]


class _IrqLow:
    """Control lines with IRQ held low and the bus always free (the interface step_timed reads)."""
    nmi_next = 1 << 62
    irq_next = 0

    def ba_free(self, cycle):
        return 1 << 30

    def ba_wait(self, cycle):
        return 0

    def nmi_edge(self, cycle):
        return False

    def irq_low(self, cycle):
        return True


@pytest.mark.parametrize("cpu_class, d_after", [(MPU65C02, 0), (MPU6510, FLAG_D)])
def test_an_interrupt_clears_decimal_mode_on_the_65c02_only(cpu_class, d_after):
    memory = [0xEA] * 0x10000
    memory[0xFFFE:0x10000] = [0x00, 0xD0]
    mpu = cpu_class(memory=memory, pc=0xC000)
    mpu.p = 0x20 | FLAG_D  # I clear
    mpu.lines = _IrqLow()
    assert mpu.step_timed() and mpu.pending_interrupt == "IRQ"
    assert not mpu.step_timed()  # the interrupt sequence
    assert mpu.pc == 0xD000 and mpu.p & FLAG_D == d_after and mpu.memory[0x100 + mpu.sp + 1] & FLAG_D


OPHIS_65C02 = """; sum of the bytes a pointer in zero page points at (count in X), in Ophis syntax with 65C02 opcodes
.org $1000
sum:
    stz total
    ldy #0
loop:
    lda (ptr),y
    clc
    adc total
    sta total
    iny
    dex
    bne loop
    bra done
    brk
done:
    rts
.alias ptr $20
.alias total $22
"""


def test_an_ophis_source_for_the_65c02_is_assembled_with_its_opcodes(tmp_path, capsys):
    (tmp_path / "sum.s").write_text(OPHIS_65C02)
    (tmp_path / "ref.py").write_text("def total(a, b, c, count, pointer):\n    return (a + b + c) & 0xFF\n")
    spec = {"program": {"file": "sum.s", "entry": "sum", "cpu": "65c02", "init": None},
            "inputs": {"a": "$3000", "b": "$3001", "c": "$3002", "count": {"at": "X", "values": "3..3"},
                       "pointer": {"at": "$20", "size": 2, "values": [0x3000]}},
            "outputs": {"total": "$22"}, "reference": {"function": "ref.py:total"},
            "cases": {"random": 300, "seed": 1}, "cycles": {"loops": {"loop": 3}}}
    del spec["program"]["init"]
    report = check(spec_from_dict(spec, base=tmp_path))
    assert report.mismatches == 0 and report.totals.cases == 300
    # STZ 3, LDY 2, three rounds of (5 + 2 + 3 + 3 + 2 + 2 + 3) - 1 for the last BNE, BRA 3, RTS 6
    assert report.totals.cycles_min == report.totals.cycles_max == 3 + 2 + 3 * 20 - 1 + 3 + 6
    code = main(["run", str(tmp_path / "sum.s"), "--entry", "sum"])
    assert code == 2 and "sum.s:" in capsys.readouterr().err  # on the 6510 Ophis refuses STZ


def test_retro_check_refuses_a_scene_for_a_65c02_routine(capsys):
    code = main(["check", str(EXAMPLE / "hit65.toml"), "--scene", str(EXAMPLE.parent / "vic_two_balls.toml"),
                 "--random", "10", "--jobs", "1"])
    err = capsys.readouterr().err
    assert code == 2 and "a 6510 scene cannot run the 65c02 routine hit65" in err and err.count("\n") == 1


def test_a_bit_branch_routine_checks_exhaustively_on_both_engines(tmp_path):
    """BBS7 splits the lanes of the batched core; Machine and the timing model agree on every case."""
    code = [0xFF, 0x10, 0x05,        # $1000 BBS7 $10, $1008
            0x64, 0x11,              # $1003 STZ $11
            0x80, 0x05,              # $1005 BRA $100C
            0x00,                    # $1007 BRK (never reached)
            0xA9, 0x01, 0x85, 0x11,  # $1008 LDA #1; STA $11
            0x60]                    # $100C RTS
    (tmp_path / "sign.bin").write_bytes(bytes(code))
    (tmp_path / "ref.py").write_text("def negative(v):\n    return int(v >= 128)\n")
    spec = {"program": {"file": "sign.bin", "load": "$1000", "entry": "$1000", "cpu": "65c02"},
            "inputs": {"v": "$10"}, "outputs": {"negative": "$11"}, "reference": {"function": "ref.py:negative"},
            "cases": {"exhaustive": ["v"]}}
    report = check_routine(spec_from_dict(spec, base=tmp_path), exhaustive=True, random_count=0, engine="batch")
    assert report.engine == "batch" and report.mismatches == 0 and report.totals.cases == 256
    assert report.agreement.engine_cases == 256 and report.agreement.engine_mismatches == 0
    assert report.totals.cycles_min == report.totals.cycles_max == 5 + 3 + 3 + 6 == 5 + 1 + 2 + 3 + 6
    assert (report.static.best, report.static.worst) == (17, 17)


def test_retro_asm_with_cpu_65c02_writes_the_65c02_opcodes(tmp_path, capsys):
    source = tmp_path / "clear.s"
    source.write_text(".org $1000\nclear:\n    stz $10\n    lda ($12)\n    inc\n    bra +\n    nop\n*   rts\n")
    assert main(["asm", str(source), "-o", str(tmp_path / "clear.prg"), "--cpu", "65C02"]) == 0
    assert (tmp_path / "clear.prg").read_bytes() == bytes([0x00, 0x10, 0x64, 0x10, 0xB2, 0x12, 0x1A, 0x80, 0x01,
                                                           0xEA, 0x60])
    capsys.readouterr()
    assert main(["asm", str(source), "-o", str(tmp_path / "other.prg"), "--cpu", "z80"]) == 2
    err = capsys.readouterr().err
    assert "--cpu: expected one of 6510, 2a03, 65c02, got 'z80'" in err and err.count("\n") == 1
    assert main(["asm", str(source), "-o", str(tmp_path / "other.prg")]) == 2  # STZ is no NMOS opcode
    assert not (tmp_path / "other.prg").exists()


@pytest.mark.parametrize("engine", ["scalar", "batch"])
def test_expected_rows_of_a_65c02_routine_are_timed_by_the_65c02_model(tmp_path, engine):
    """A row's call on Machine is held against the 65C02 timing model (BRA is 3 cycles there; the
    NMOS table reads $80 as a 2-cycle NOP #imm, which would make every row a cycle mismatch)."""
    code = [0xFF, 0x10, 0x05, 0x64, 0x11, 0x80, 0x05, 0x00, 0xA9, 0x01, 0x85, 0x11, 0x60]  # as above
    (tmp_path / "sign.bin").write_bytes(bytes(code))
    spec = {"program": {"file": "sign.bin", "load": "$1000", "entry": "$1000", "cpu": "65c02"},
            "inputs": {"v": "$10"}, "outputs": {"negative": "$11"},
            "rows": [{"v": 5, "negative": 0, "cycles": 5 + 3 + 3 + 6}, {"v": 200, "negative": 1, "cycles": 17}]}
    report = check_routine(spec_from_dict(spec, base=tmp_path), engine=engine)
    assert report.totals.cases == 2 and report.totals.cycle_mismatches == 0 and report.mismatches == 0
    assert report.rows.wrong == 0 and (report.static.best, report.static.worst) == (17, 17)
    if engine == "batch":
        assert report.agreement.cycle_mismatches == 0 and report.agreement.engine_cases == 2
