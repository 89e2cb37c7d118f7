"""The compiled engine (retro.cpu.translate + retro.cpu.compiled) against the batched core and Machine on
randomly generated routines: straight-line code over every opcode the engines run, forward and
backward branches, a subroutine, decimal mode (P set from the data by PHA/PLP, and SED), page
crossings; every call's registers, flags, cycles and memory compared on all three engines. And the
cache: a second build loads instead of compiling, a corrupt or foreign entry is rebuilt."""

from __future__ import annotations

import json
import random

import numpy as np
import pytest

from retro.cpu import compiled as compiled_module
from retro.cpu.batch import BatchCpu, LaneError
from retro.cpu.compiled import SET_A, SET_FLAG, SET_P, SET_X, SET_Y, compile_routine, numba_problem
from retro.cpu.machine import CALL_STACK_TOP, RETURN_TRAP, push_return_trap
from retro.cpu.opcodes import DOCUMENTED, MODE_LENGTH, RESERVED, STABLE
from retro.cpu.translate import FALLBACK, Untranslatable, tables_for, translate
from retro.errors import RunError
from retro.machines import build_machine

pytestmark = pytest.mark.skipif(numba_problem() is not None, reason=f"{numba_problem()}")

CODE = 0xC0A0  # the routines cross into the next page: branches across it cost their extra cycle
ZERO_PAGE = range(0x00, 0x100)
DATA = range(0x0300, 0x0500)  # absolute operands and (zp),Y pointers land here (page crossings included)
STACK = range(0x0100, 0x0200)
LANES = 160
BUDGET = 4_000
CONTROL = {"JMP", "JSR", "RTS", "RTI", "BRK", "TXS", "STP", "WAI", "PHA", "PHP", "PLA", "PLP", "PHX", "PHY",
           "PLX", "PLY"}


def _pool(cpu: str) -> list[int]:
    kinds = (DOCUMENTED, STABLE, RESERVED)
    return [op for op, row in tables_for(cpu).items()
            if row.kind in kinds and row.mnemonic not in CONTROL and row.mode not in ("rel", "zpr", "ind", "iax")]


def _operand(rng: random.Random, mode: str) -> list[int]:
    if mode in ("zpg", "zpx", "zpy", "inx", "iny", "zpi"):
        return [rng.randrange(0x20, 0x40)]
    if mode in ("abs", "abx", "aby"):
        return list((rng.randrange(0x0300, 0x0400)).to_bytes(2, "little"))
    if mode == "imm":
        return [rng.randrange(256)]
    return []


def random_program(cpu: str, seed: int, length: int = 70, decimal: bool = True) -> bytes:
    """Random instructions with branches (forward, and backward in counted loops), a JSR, P from the
    data (LDA zp; PHA; PLP: D and the other flags vary per call) and SED (neither when not `decimal`:
    code that cannot set D); ends with RTS."""
    rng = random.Random(seed)
    pool = _pool(cpu)
    table = tables_for(cpu)
    branches = [op for op, row in table.items() if row.mode == "rel" and row.mnemonic != "BRA"]
    items: list = []  # bytes, or ("branch", opcode, label) / ("label", name)
    labels = 0
    for _ in range(length):
        roll = rng.random()
        if roll < 0.08:  # a forward branch over a few instructions
            labels += 1
            items.append(("branch", rng.choice(branches), labels))
            for _ in range(rng.randrange(1, 4)):
                op = rng.choice(pool)
                items.append(bytes([op, *_operand(rng, table[op].mode)]))
            items.append(("label", labels))
        elif roll < 0.14 and not decimal:
            items.append(bytes([0xD8, 0x18]))  # CLD; CLC
        elif roll < 0.12:  # flags from the data, decimal mode included
            items.append(bytes([0xA5, rng.randrange(0x20, 0x40), 0x48, 0x28]))  # LDA zp; PHA; PLP
        elif roll < 0.14:
            items.append(bytes([0xF8]))  # SED
        elif roll < 0.16:  # a counted loop: LDY #n; body (Y untouched); DEY; BNE back
            labels += 1
            items.append(bytes([0xA0, rng.randrange(1, 5)]))
            items.append(("label", labels))
            for _ in range(rng.randrange(1, 3)):
                op = rng.choice([o for o in pool if "Y" not in table[o].mnemonic and table[o].mode not in ("aby", "zpy", "iny")])
                items.append(bytes([op, *_operand(rng, table[op].mode)]))
            items.append(bytes([0x88]))
            items.append(("branch", 0xD0, labels))
        elif roll < 0.18:
            items.append(("jsr",))
        else:
            op = rng.choice(pool)
            items.append(bytes([op, *_operand(rng, table[op].mode)]))
    items.append(bytes([0x60]))
    subroutine = bytes([0xE8, 0x69, rng.randrange(256), 0x60])  # INX; ADC #imm; RTS
    # layout: two passes (branches are 2 bytes, JSR 3)
    address, where = CODE, {}
    for item in items:
        if isinstance(item, bytes):
            address += len(item)
        elif item[0] == "label":
            where[item[1]] = address
        else:
            address += 2 if item[0] == "branch" else 3
    sub_at = address
    code = bytearray()
    for item in items:
        if isinstance(item, bytes):
            code += item
        elif item[0] == "branch":
            offset = where[item[2]] - (CODE + len(code) + 2)
            assert -128 <= offset <= 127
            code += bytes([item[1], offset & 0xFF])
        elif item[0] == "jsr":
            code += bytes([0x20, sub_at & 0xFF, sub_at >> 8])
    return bytes(code + subroutine)


def random_states(seed: int, n: int):
    """Per call: A, X, Y, P and the bytes of zero page and the data pages ((zp) pointers into DATA)."""
    rng = np.random.default_rng(seed)
    registers = rng.integers(0, 256, size=(n, 4))
    zero_page = rng.integers(0, 256, size=(n, 256))
    zero_page[:, 1::2] = rng.integers(0x03, 0x05, size=(n, 128))  # every pointer's high byte: $03 or $04
    data = rng.integers(0, 256, size=(n, len(DATA)))
    return registers, np.concatenate([zero_page, data], axis=1)


PLACED = np.asarray(list(ZERO_PAGE) + list(DATA), dtype=np.int64)
WATCHED = np.asarray(list(ZERO_PAGE) + list(STACK) + list(DATA), dtype=np.int64)


def image_with(code: bytes) -> bytearray:
    image = bytearray(0x10000)
    image[CODE:CODE + len(code)] = code
    return image


def on_machine(cpu: str, code: bytes, registers, memory) -> list:
    machine = build_machine(cpu=cpu)
    image = image_with(code)
    results = []
    for (a, x, y, p), values in zip(registers.tolist(), memory.tolist()):
        machine.memory[:] = list(image)
        for address, value in zip(PLACED.tolist(), values):
            machine.memory[address] = value
        try:
            call = machine.call(CODE, a=a, x=x, y=y, p=p, budget=BUDGET)
        except RunError:
            results.append(None)
            continue
        results.append((call.a, call.x, call.y, call.p & 0xCF, call.cycles,
                        tuple(machine.memory[address] for address in WATCHED.tolist())))
    return results


def on_batch(cpu: str, code: bytes, registers, memory, watched=WATCHED) -> list:
    image = image_with(code)
    sp = push_return_trap(image)
    n = len(registers)
    batch = BatchCpu(cpu, bytes(image), n)
    lanes = np.repeat(np.arange(n), len(PLACED))
    batch.memory.write(lanes, np.tile(PLACED, n), memory.ravel())
    batch.a[:], batch.x[:], batch.y[:] = registers[:, 0], registers[:, 1], registers[:, 2]
    batch.p[:] = (registers[:, 3] | 0x20) & ~0x10
    batch.sp[:] = sp
    batch.call(CODE, BUDGET, RETURN_TRAP, CALL_STACK_TOP)
    watched = np.stack([batch.read(int(address)) for address in watched], axis=1)
    return [None if batch.error[i] else
            (int(batch.a[i]), int(batch.x[i]), int(batch.y[i]), int(batch.p[i]) & 0xCF, int(batch.cycles[i]),
             tuple(watched[i].tolist())) for i in range(n)]


def on_compiled(cpu: str, code: bytes, registers, memory, watched=WATCHED, p: int | None = None,
                decimal_entry: bool = False) -> tuple[list, int]:
    """(results, calls left to the batched core); a call stopped by the budget is None. `p`: P the
    same for every call, in the base registers (no column sets P), registers[:, 3] ignored."""
    image = image_with(code)
    sp = push_return_trap(image)
    sets = ((0, 0, SET_A), (1, 0, SET_X), (2, 0, SET_Y)) + (((3, 0, SET_P),) if p is None else ())
    routine = compile_routine(bytes(image), CODE, cpu, RETURN_TRAP, columns=4, sets=sets, decimal_entry=decimal_entry)
    flags = ((registers[:, 3] | 0x20) & ~0x10).astype(np.int64)
    columns = (*(np.ascontiguousarray(registers[:, k], dtype=np.int64) for k in range(3)), flags)
    base = np.asarray([0, 0, 0, 0 if p is None else p], dtype=np.int64)
    done = routine.run(bytes(image), columns, base, sp, BUDGET, RETURN_TRAP, CALL_STACK_TOP,
                       np.asarray(watched, dtype=np.int64), PLACED, np.ascontiguousarray(memory.T.astype(np.uint8)))
    results, left = [], 0
    for i in range(len(registers)):
        status = int(done["status"][i])
        if status >= FALLBACK:
            left += 1
            results.append("fallback")
        elif status == LaneError.BUDGET:
            results.append(None)
        else:
            results.append((int(done["a"][i]), int(done["x"][i]), int(done["y"][i]), int(done["p"][i]) & 0xCF,
                            int(done["cycles"][i]), tuple(done["bytes"][:, i].tolist())))
    return results, left


def _differences(name: str, one: list, other: list) -> list[str]:
    found = []
    for i, (a, b) in enumerate(zip(one, other)):
        if a != "fallback" and b != "fallback" and a != b:
            found.append(f"call {i}: {name}: {a if a is None else a[:5]} != {b if b is None else b[:5]}"
                         + ("" if a is None or b is None or a[5] == b[5] else " (memory differs)"))
    return found


@pytest.mark.parametrize("cpu,seed", [(cpu, seed) for cpu in ("6510", "2a03", "65c02") for seed in range(2)])
def test_random_routines_agree_on_all_three_engines(cpu, seed, compiled_cache):
    code = random_program(cpu, seed * 3 + ("6510", "2a03", "65c02").index(cpu))
    registers, memory = random_states(seed, LANES)
    compiled, left = on_compiled(cpu, code, registers, memory)
    batch = on_batch(cpu, code, registers, memory)
    machine = on_machine(cpu, code, registers, memory)
    problems = _differences("compiled vs batch", compiled, batch) + _differences("batch vs Machine", batch, machine)
    assert not problems, "\n".join(problems[:10])
    assert left < LANES // 4  # nearly every call ran compiled (a (zp),Y store may land in the code: batched)
    assert sum(r is not None for r in machine) > LANES // 2


def _run_known(code: bytes, registers) -> dict:
    """The code compiled as the runner compiles it (no lane bytes, no output bytes: both known, empty),
    A, X, Y and P from the columns; its run's rows."""
    image = image_with(code)
    sp = push_return_trap(image)
    sets = ((0, 0, SET_A), (1, 0, SET_X), (2, 0, SET_Y), (3, 0, SET_P))
    routine = compile_routine(bytes(image), CODE, "6510", RETURN_TRAP, columns=4, sets=sets, lanes=(), outputs=())
    columns = tuple(np.ascontiguousarray(registers[:, k], dtype=np.int64) for k in range(4))
    return routine.run(bytes(image), columns, np.zeros(4, dtype=np.int64), sp, BUDGET, RETURN_TRAP, CALL_STACK_TOP,
                       np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros((0, len(registers)), dtype=np.uint8))


def test_a_leaf_routine_returns_directly_and_agrees_with_the_batched_core(compiled_cache):
    """CMP #$40; BCC +2; ADC #$22; TAX; RTS compiled for known lanes: no JSR, push, pull or store to a
    computed address, so its RTS is the call's return (`direct`: no stack read); every call agrees
    with the batched core."""
    code = bytes([0xC9, 0x40, 0x90, 0x02, 0x69, 0x22, 0xAA, 0x60])
    image = image_with(code)
    push_return_trap(image)
    assert "direct = True and" in translate(image.__getitem__, CODE, "6510", RETURN_TRAP, lanes=()).source
    registers, memory = random_states(3, LANES)
    done = _run_known(code, registers)
    compiled = [(int(done["a"][i]), int(done["x"][i]), int(done["y"][i]), int(done["p"][i]) & 0xCF,
                 int(done["cycles"][i])) for i in range(LANES)]
    assert done["status"].tolist() == [0] * LANES
    assert compiled == [r[:5] for r in on_batch("6510", code, registers, memory)]


def _stack_top() -> int:
    return push_return_trap(image_with(b""))


@pytest.mark.parametrize("code,why", [
    (bytes([0x68, 0x68, 0x60]), "PLA; PLA; RTS: the RTS takes what lies above the return address"),
    (bytes([0xBA, 0xA9, 0x50, 0x9D, 0x01, 0x01, 0x60]), "TSX; LDA #$50; STA $0101,X; RTS: a computed store "
                                                          "rewrites the return address"),
    (bytes([0xA9, 0x50, 0x8D, 0x01 + _stack_top(), 0x01, 0x60]), "LDA #$50; STA $01xx; RTS: a fixed store "
                                                                 "rewrites the return address"),
])
def test_a_return_address_moved_or_rewritten_is_not_taken_for_the_callers(code, why, compiled_cache):
    """The caller's return is taken without reading the stack only where nothing can move S or write
    page 1: here the RTS goes to $xx51 or above the trap, where no block starts, and the call is left
    to the batched core (not returned with the registers as they are)."""
    done = _run_known(code, np.array([[0, 0, 0, 0x20]] * 4))
    assert done["status"].tolist() == [FALLBACK + 2] * 4, why


@pytest.mark.parametrize("cpu", ["6510", "65c02"])
def test_code_that_cannot_set_d_runs_binary_and_leaves_a_call_entered_with_d_set(cpu, compiled_cache):
    """No SED, no PLP, no column sets P: ADC and SBC are translated for binary mode only (inline), the
    same as the batched core on every call entered with D clear; entered with D set, every call is
    left to the batched core (which gets it right: decimal mode)."""
    code = random_program(cpu, 11, decimal=False)
    registers, memory = random_states(5, LANES)
    clear = 0x21  # carry set, D clear
    registers[:, 3] = clear
    compiled, left = on_compiled(cpu, code, registers, memory, p=clear)
    problems = _differences("compiled vs batch", compiled, on_batch(cpu, code, registers, memory))
    assert not problems, "\n".join(problems[:10])
    assert left < LANES // 4
    image = image_with(code)
    source = translate(image.__getitem__, CODE, cpu, RETURN_TRAP, sets=((0, 0, SET_A),)).source
    assert "t = a + " in source and "_nmos(" not in source and "_cmos(" not in source  # ADC/SBC inline, binary
    decimal = clear | 0x08
    compiled, left = on_compiled(cpu, code, registers, memory, p=decimal)
    assert left == LANES and set(compiled) == {"fallback"}


@pytest.mark.parametrize("cpu", ["6510", "65c02"])
def test_code_compiled_for_calls_entered_with_d_set_keeps_decimal_mode(cpu, compiled_cache):
    """The same code as above, compiled knowing calls start with D set (a spec whose P has D): ADC and
    SBC keep decimal mode, the results equal the batched core's, and the calls are not left to it."""
    code = random_program(cpu, 11, decimal=False)
    registers, memory = random_states(5, LANES)
    registers[:, 3] = 0x29  # carry and D set
    compiled, left = on_compiled(cpu, code, registers, memory, p=0x29, decimal_entry=True)
    problems = _differences("compiled vs batch", compiled, on_batch(cpu, code, registers, memory))
    assert not problems, "\n".join(problems[:10])
    assert left < LANES // 4


def test_code_without_adc_or_sbc_runs_compiled_when_entered_with_d_set(compiled_cache):
    """D matters only to ADC and SBC: code with neither is not left to the batched core for D."""
    code = bytes([0xA9, 0x05, 0x09, 0x33, 0x60])  # LDA #$05 / ORA #$33 / RTS
    registers, memory = random_states(6, 8)
    registers[:, 3] = 0x28
    compiled, left = on_compiled("6510", code, registers, memory, p=0x28)
    assert left == 0 and compiled == on_batch("6510", code, registers, memory)


def test_d_set_by_plp_is_decimal_mode_though_no_column_sets_p(compiled_cache):
    """LDA $20; PHA; PLP (P from the data: D on about half the calls); LDA $22; ADC $24; STA $40; PHP;
    PLA; STA $41; RTS, entered with D clear and no P column: PLP can set D, so the code keeps its
    decimal ADC (the same results and flags as the batched core)."""
    code = bytes([0xA5, 0x20, 0x48, 0x28, 0xA5, 0x22, 0x65, 0x24, 0x85, 0x40, 0x08, 0x68, 0x85, 0x41, 0x60])
    registers, memory = random_states(7, LANES)
    registers[:, 3] = 0x20
    compiled, left = on_compiled("6510", code, registers, memory, [0x40, 0x41], p=0x20)
    assert left == 0 and sum((m & 0x08) != 0 for m in memory[:, 0x20].tolist()) > LANES // 4
    problems = _differences("compiled vs batch", compiled, on_batch("6510", code, registers, memory, [0x40, 0x41]))
    assert not problems, "\n".join(problems[:10])


def test_decimal_mode_on_every_operand_pair(compiled_cache):
    """SED; ADC, SBC (and ARR on the NMOS) of every A, every third operand and both carries, results and
    flags stored, against the batched core: the 6510's NMOS decimal mode, the 2A03's binary, the 65C02's
    (one cycle more)."""
    pairs = np.array([(a, v, c) for a in range(256) for v in range(0, 256, 3) for c in (0, 1)])
    zeros = np.zeros(len(pairs), dtype=np.int64)
    registers = np.stack([pairs[:, 0], zeros, zeros, pairs[:, 2]], axis=1)  # A, X, Y, P (the carry)
    memory = np.zeros((len(pairs), len(PLACED)), dtype=np.int64)
    memory[:, 0x21] = pairs[:, 1]
    for cpu in ("6510", "2a03", "65c02"):
        code = bytes([0xF8, 0x08, 0x85, 0x40,  # SED; PHP (the input P); STA $40
                      0x65, 0x21, 0x85, 0x41, 0x08, 0x68, 0x85, 0x42, 0x28,  # ADC $21; A, P -> $41, $42; PLP
                      0x08, 0xA5, 0x40, 0xE5, 0x21, 0x85, 0x43, 0x08, 0x68, 0x85, 0x44, 0x28])  # SBC $21 -> $43, $44
        if cpu == "6510":
            code += bytes([0xA5, 0x40, 0x6B, 0xFF, 0x85, 0x45, 0x08, 0x68, 0x85, 0x46])  # ARR #$FF -> $45, $46
        code += bytes([0x60])
        results = list(range(0x40, 0x47))
        compiled, left = on_compiled(cpu, code, registers, memory, results)
        batch = on_batch(cpu, code, registers, memory, results)
        assert left == 0
        problems = _differences(cpu, compiled, batch)
        assert not problems, "\n".join(problems[:10])


def test_a_store_into_the_code_leaves_the_call_to_the_batched_core(compiled_cache):
    # STA ($20),Y with the pointer at the code: the write lands in the routine's own bytes
    code = bytes([0x91, 0x20, 0xA9, 0x01, 0x60])
    registers = np.array([[7, 0, 0, 0x20], [7, 0, 0, 0x20]])
    memory = np.zeros((2, len(PLACED)), dtype=np.int64)
    memory[0, 0x20:0x22] = (0x03, 0x03)  # call 0 writes data
    memory[1, 0x20:0x22] = (0xA2, 0xC0)  # call 1 writes $C0A2: LDA's opcode
    compiled, left = on_compiled("6510", code, registers, memory)
    assert left == 1 and compiled[1] == "fallback" and compiled[0][0] == 1


@pytest.mark.parametrize("code,written,why", [
    (bytes([0x8D, 0xA3, 0xC0, 0xA9, 0x00, 0x60]), 0xC0A3, "an opcode byte"),  # STA $C0A3: LDA's opcode
    (bytes([0xEE, 0xA4, 0xC0, 0x90, 0x00, 0x60]), 0xC0A4,  # INC $C0A4: BCC's offset
     r"an operand byte of the instruction at \$C0A3: a branch's offset"),
    (bytes([0x8D, 0xA4, 0xC0, 0x20, 0xA6, 0xC0, 0x60]), 0xC0A4,  # STA $C0A4: JSR's target
     r"an operand byte of the instruction at \$C0A3: a branch's offset, a JSR's target"),
])
def test_a_fixed_store_into_an_opcode_or_a_decoded_operand_is_refused_with_its_reason(code, written, why):
    image = image_with(code)
    with pytest.raises(Untranslatable, match=rf"self-modifying code: the instruction at \$C0A0 writes \${written:04X}, {why}"):
        compile_routine(bytes(image), CODE, "6510", RETURN_TRAP)


def test_the_cache_loads_the_second_time_and_rebuilds_a_corrupt_or_foreign_entry(tmp_path, monkeypatch):
    monkeypatch.setenv("RETRO_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled_module, "_LOADED", {})
    code = bytes([0xA9, 0x05, 0x69, 0x03, 0x60])  # LDA #5; ADC #3; RTS
    image = bytes(image_with(code))
    first = compile_routine(image, CODE, "2a03", RETURN_TRAP)
    assert not first.from_cache
    monkeypatch.setattr(compiled_module, "_LOADED", {})
    second = compile_routine(image, CODE, "2a03", RETURN_TRAP)
    assert second.from_cache
    (entry,) = (tmp_path / "compiled").iterdir()
    data = next(entry.rglob("*.nbc"))
    data.write_bytes(b"not numba's" + data.read_bytes()[11:])  # corrupt: the sums no longer match
    monkeypatch.setattr(compiled_module, "_LOADED", {})
    third = compile_routine(image, CODE, "2a03", RETURN_TRAP)
    assert not third.from_cache
    manifest = entry / "manifest.json"
    record = json.loads(manifest.read_text())
    manifest.write_text(json.dumps({**record, "key": "0" * 64}))  # another key's manifest: foreign
    monkeypatch.setattr(compiled_module, "_LOADED", {})
    assert not compile_routine(image, CODE, "2a03", RETURN_TRAP).from_cache
    monkeypatch.setattr(compiled_module, "_LOADED", {})
    assert compile_routine(image, CODE, "2a03", RETURN_TRAP).from_cache


def test_a_runaway_call_stops_at_the_budget(compiled_cache):
    code = bytes([0xE8, 0x4C, 0xA0, 0xC0])  # INX; JMP $C0A0
    compiled, left = on_compiled("6510", code, np.array([[0, 0, 0, 0x20]]), np.zeros((1, len(PLACED)), dtype=np.int64))
    assert compiled == [None] and left == 0


def test_a_jump_to_itself_stops_at_the_budget(compiled_cache):
    """JMP $C0A0 at $C0A0: a jump to the same address goes through the budget's check (a forward jump
    alone skips it)."""
    compiled, left = on_compiled("6510", bytes([0x4C, 0xA0, 0xC0]), np.array([[0, 0, 0, 0x20]]),
                                 np.zeros((1, len(PLACED)), dtype=np.int64))
    assert compiled == [None] and left == 0


def test_a_taken_branch_into_the_next_page_costs_two_cycles_more(compiled_cache):
    """NOP x4 at $C0F8; BCS $C102 at $C0FC (the next instruction at $C0FE, the target in page $C1);
    LDA #1; TAX; NOP; RTS. By hand: not taken 8 + 2 + 2 + 2 + 2 + 6 = 22 cycles; taken 8 + 2 + 1 + 1
    + 6 = 18."""
    start = 0xC0F8
    code = bytes([0xEA] * 4 + [0xB0, 0x04, 0xA9, 0x01, 0xAA, 0xEA, 0x60])
    image = bytearray(0x10000)
    image[start:start + len(code)] = code
    sp = push_return_trap(image)
    routine = compile_routine(bytes(image), start, "6510", RETURN_TRAP, columns=1, sets=((0, 1, SET_FLAG),))
    carry = np.array([0, 1], dtype=np.int64)  # carry clear, carry set
    done = routine.run(bytes(image), (carry,), np.asarray([0, 0, 0, 0x20], dtype=np.int64), sp, BUDGET, RETURN_TRAP,
                       CALL_STACK_TOP, np.zeros(0, dtype=np.int64))
    assert done["cycles"].tolist() == [22, 18] and done["status"].tolist() == [0, 0]


def test_a_return_into_an_inlined_block_falls_back_instead_of_spinning(compiled_cache):
    """LDA #$C0; PHA; LDA #$A9; PHA (a return address: $C0AA); CLC; BCC $C0AA; RTS; $C0AA: LDA #7; RTS.
    $C0AA has one way in by its code (the branch), so its code is translated inside the first block;
    the first RTS returns there at run time. That call must come back (left to the batched core), never
    spin in the dispatch (it did: the budget is only looked at between blocks)."""
    code = bytes([0xA9, 0xC0, 0x48, 0xA9, 0xA9, 0x48, 0x18, 0x90, 0x01, 0x60, 0xA9, 0x07, 0x60])
    registers = np.array([[0, 0, 0, 0x20]])
    memory = np.zeros((1, len(PLACED)), dtype=np.int64)
    compiled, left = on_compiled("6510", code, registers, memory)
    assert left == 1 and compiled == ["fallback"]
    assert on_batch("6510", code, registers, memory)[0][0] == 7


# ---- self-modifying code that patches operands ------------------------------------------------------------

OPERAND_MODES = ("imm", "zpg", "zpx", "zpy", "abs", "abx", "aby", "inx", "iny", "zpi")
PATCH_STORES = {"6510": [0x8D, 0x8E, 0x8C, 0x8F, 0xEE, 0xCE, 0x0E, 0x2E, 0x4E, 0x6E, 0xCF, 0xEF],  # STA..SAX, RMW, DCP, ISC
                "2a03": [0x8D, 0x8E, 0x8C, 0xEE, 0xCE, 0x0E, 0x2E, 0x4E, 0x6E],
                "65c02": [0x8D, 0x8E, 0x8C, 0xEE, 0xCE, 0x0E, 0x2E, 0x4E, 0x6E, 0x9C, 0x0C, 0x1C]}  # STZ, TSB, TRB


def random_smc_program(cpu: str, seed: int, length: int = 34) -> bytes:
    """Random instructions with operands, and stores at fixed addresses into their operand bytes (before
    them, and after them inside counted loops, so a patch made on one pass is read on the next): STA of
    A masked to $03-$04 into an absolute high byte (the data pages) or to $20-$3F into a zero-page
    operand, any store or read-modify-write of any value into an immediate or a low byte (page
    crossings either way); reads of the patched bytes (LDA abs of a code byte); now and then STA abs,X
    into the code, X 2 or 3 from the data (landing on a patched operand when X is 3, on the byte before it else: an
    opcode makes that call fall back); forward branches. Ends with RTS."""
    rng = random.Random(seed)
    table = tables_for(cpu)
    pool = [op for op in _pool(cpu) if table[op].mode in OPERAND_MODES and not (cpu == "65c02" and table[op].kind == RESERVED)]
    loop_pool = [op for op in pool if "Y" not in table[op].mnemonic and table[op].mode not in ("aby", "zpy", "iny")]
    items: list = []  # ["op", bytes] / ["patch", store opcode] / ["peek"] / ["poke"] / ["branch", opcode, label] / ["label", n]
    labels = 0
    for _ in range(length):
        roll = rng.random()
        if roll < 0.3:
            items.append(["patch", rng.choice(PATCH_STORES[cpu])])
        elif roll < 0.36:
            items.append(["peek"])
        elif roll < 0.40:
            labels += 1
            items.append(["branch", rng.choice([0x90, 0xB0, 0xD0, 0xF0, 0x10, 0x30]), labels])
            op = rng.choice(pool)
            items.append(["op", bytes([op, *_operand(rng, table[op].mode)])])
            items.append(["label", labels])
        elif roll < 0.46:  # a counted loop whose body patches itself
            labels += 1
            items.append(["op", bytes([0xA0, rng.randrange(1, 4)])])
            items.append(["label", labels])
            for _ in range(rng.randrange(2, 5)):
                if rng.random() < 0.5:
                    items.append(["patch", rng.choice(PATCH_STORES[cpu])])
                else:
                    op = rng.choice(loop_pool)
                    items.append(["op", bytes([op, *_operand(rng, table[op].mode)])])
            items.append(["op", bytes([0x88])])
            items.append(["branch", 0xD0, labels])
        elif roll < 0.48:
            items.append(["poke"])
        else:
            op = rng.choice(pool)
            items.append(["op", bytes([op, *_operand(rng, table[op].mode)])])
    items.append(["op", bytes([0x60])])
    operands = [k for k, item in enumerate(items) if item[0] == "op" and len(item[1]) > 1]
    target_of, mask_of = {}, {}  # per patch, peek and poke: (item, byte 1 or 2); per patch: (AND, ORA) or None
    for k, item in enumerate(items):
        if item[0] in ("patch", "peek"):
            target = rng.choice(operands)
            target_of[k] = (target, rng.randrange(1, len(items[target][1])))
        if item[0] == "patch":
            mode = table[items[target][1][0]].mode
            high = mode in ("abs", "abx", "aby") and target_of[k][1] == 2
            mask_of[k] = (0x01, 0x03) if high else (0x1F, 0x20) if mode not in ("imm", "abs", "abx", "aby") else None
            if mask_of[k]:
                item[1] = 0x8D  # STA of the masked A

    patched = sorted({target_of[k] for k, item in enumerate(items) if item[0] == "patch"})
    for k, item in enumerate(items):
        if item[0] == "poke":  # onto a patched operand (a live instruction's), or the byte before it
            target_of[k] = rng.choice(patched) if patched else (operands[0], 1)

    def length_of(k: int, item) -> int:
        if item[0] == "op":
            return len(item[1])
        if item[0] == "patch":
            return 7 if mask_of[k] else 3
        return {"peek": 3, "poke": 10, "branch": 2, "label": 0}[item[0]]

    address, at, where = CODE, {}, {}
    for k, item in enumerate(items):
        at[k] = address
        if item[0] == "label":
            where[item[1]] = address
        address += length_of(k, item)
    code = bytearray()
    for k, item in enumerate(items):
        assert CODE + len(code) == at[k]
        if item[0] == "op":
            code += item[1]
        elif item[0] == "branch":
            offset = where[item[2]] - (CODE + len(code) + 2)
            code += bytes([item[1], offset & 0xFF])
        elif item[0] != "label":
            target, byte = target_of[k]
            written = at[target] + byte
            if item[0] == "patch":
                if mask_of[k]:
                    code += bytes([0x29, mask_of[k][0], 0x09, mask_of[k][1]])  # AND #; ORA #
                code += bytes([item[1], *written.to_bytes(2, "little")])
            elif item[0] == "peek":
                code += bytes([0xAD, *written.to_bytes(2, "little")])  # LDA abs: the operand byte as it is now
            else:  # poke: X = 2 or 3 from the data (LDA $20; AND #1; ORA #2; TAX), STA base,X: on the chosen byte when X is 3
                code += bytes([0xA5, 0x20, 0x29, 0x01, 0x09, 0x02, 0xAA, 0x9D, *(written - 3).to_bytes(2, "little")])
    return bytes(code)


@pytest.mark.parametrize("cpu,seed", [(cpu, seed) for cpu in ("6510", "2a03", "65c02") for seed in range(2)])
def test_random_self_modifying_routines_agree_on_all_three_engines(cpu, seed, compiled_cache):
    """Routines that patch their own operands (`random_smc_program`) are compiled, not refused; every call
    agrees with the batched core and Machine (registers, flags, cycles with the page crossings of the
    patched addresses, memory); only calls whose STA abs,X hit an opcode byte are left to the batched core."""
    code = random_smc_program(cpu, 100 + seed * 3 + ("6510", "2a03", "65c02").index(cpu))
    image = image_with(code)
    push_return_trap(image)
    assert translate(image.__getitem__, CODE, cpu, RETURN_TRAP).live_bytes  # some operands are read at run time
    compiled, left = _three_engines(cpu, code, *random_states(seed + 20, LANES))
    assert left < LANES * 2 // 3  # (a poke with X = 2 onto a patched low byte hits the opcode: about half the calls)
    assert sum(r is not None for r in compiled if r != "fallback") > LANES // 4


def _three_engines(cpu: str, code: bytes, registers, memory, watched=WATCHED) -> tuple[list, int]:
    """(the compiled engine's results, calls it left), after checking them against the batched core and
    Machine call by call."""
    compiled, left = on_compiled(cpu, code, registers, memory, watched)
    batch = on_batch(cpu, code, registers, memory, watched)
    problems = _differences("compiled vs batch", compiled, batch)
    problems += _differences("batch vs Machine", batch, on_machine(cpu, code, registers, memory))
    assert not problems, "\n".join(problems[:10])
    return compiled, left


def _data(memory, address: int) -> np.ndarray:
    """Per call, the byte the calls start with at address (the data pages, zero beyond them)."""
    if DATA.start <= address < DATA.stop:
        return memory[:, len(ZERO_PAGE) + address - DATA.start]
    return np.zeros(len(memory), dtype=np.int64)


def test_a_patched_high_byte_reads_the_page_it_names_with_its_page_crossing(compiled_cache):
    """CLC; ADC #$03; STA $C0A8 (the high byte of the next read); LDA $0380,Y; RTS, A 0 or 1: the read
    is of page $03 or $04, crossing into the next when Y >= $80. By hand: 2 + 2 + 4 + 4 (+1) + 6 =
    18-19 cycles, A the byte at $0380 + 256 A + Y."""
    code = bytes([0x18, 0x69, 0x03, 0x8D, 0xA8, 0xC0, 0xB9, 0x80, 0x03, 0x60])
    registers, memory = random_states(30, LANES)
    registers[:, 0] &= 1
    registers[:, 3] = 0x20
    compiled, left = _three_engines("6510", code, registers, memory)
    assert left == 0
    a, y = registers[:, 0], registers[:, 2]
    wanted = [int(_data(memory, 0x0380 + 256 * int(a[i]) + int(y[i]))[i]) for i in range(LANES)]
    assert [r[0] for r in compiled] == wanted
    assert [r[4] for r in compiled] == (18 + (y >= 0x80)).tolist()
    assert {r[4] for r in compiled} == {18, 19}


def test_a_patched_immediate_and_a_read_of_the_patched_byte(compiled_cache):
    """STX $C0A7 (ADC's immediate); LDY $C0A7 (the patched byte, read back); ADC #$00; RTS. By hand:
    Y = X, A = A + X + C, 4 + 4 + 2 + 6 = 16 cycles."""
    code = bytes([0x8E, 0xA7, 0xC0, 0xAC, 0xA7, 0xC0, 0x69, 0x00, 0x60])
    registers, memory = random_states(31, LANES)
    registers[:, 3] = 0x20 | (registers[:, 3] & 1)
    compiled, left = _three_engines("6510", code, registers, memory)
    assert left == 0
    a, x, c = registers[:, 0], registers[:, 1], registers[:, 3] & 1
    assert [r[:3] for r in compiled] == list(zip(((a + x + c) & 255).tolist(), x.tolist(), x.tolist()))
    assert [r[3] & 1 for r in compiled] == ((a + x + c) >> 8).tolist() and {r[4] for r in compiled} == {16}


def test_a_patch_lasts_for_its_call_only(compiled_cache):
    """BCC +5; LDA #$FF; STA $C0A8 (the low byte of the read); LDA $0300,X; RTS: the carry-set calls
    patch the read to $03FF,X, and the carry-clear calls between and after them (and a second run of
    the block) read $0300,X again: memory is the image at every call's start, as on the batched core.
    By hand: clear 3 + 4 + 6 = 13 cycles; set 2 + 2 + 4 + 4 (+1 when X > 0) + 6 = 18-19."""
    code = bytes([0x90, 0x05, 0xA9, 0xFF, 0x8D, 0xA8, 0xC0, 0xBD, 0x00, 0x03, 0x60])
    registers, memory = random_states(32, LANES)
    registers[:, 3] = 0x20 | (np.arange(LANES) % 2)  # carry clear, set, clear, ...
    compiled, left = _three_engines("6510", code, registers, memory)
    assert left == 0
    x, c = registers[:, 1], registers[:, 3] & 1
    wanted = [int(_data(memory, (0x03FF if c[i] else 0x0300) + int(x[i]))[i]) for i in range(LANES)]
    assert [r[0] for r in compiled] == wanted
    assert [r[4] for r in compiled] == np.where(c == 1, 18 + (x > 0), 13).tolist()
    image = image_with(code)
    sp = push_return_trap(image)
    routine = compile_routine(bytes(image), CODE, "6510", RETURN_TRAP, columns=2, sets=((0, 0, SET_X), (1, 0, SET_P)))
    columns = (np.ascontiguousarray(x, dtype=np.int64), np.ascontiguousarray(registers[:, 3], dtype=np.int64))
    runs = [routine.run(bytes(image), columns, np.zeros(4, dtype=np.int64), sp, BUDGET, RETURN_TRAP, CALL_STACK_TOP,
                        np.asarray([0xC0A8], dtype=np.int64), PLACED, np.ascontiguousarray(memory.T.astype(np.uint8)))
            for _ in range(2)]
    assert runs[0]["a"].tolist() == runs[1]["a"].tolist() == wanted
    assert runs[1]["bytes"][0].tolist() == np.where(c == 1, 0xFF, 0x00).tolist()  # the patched byte as each call left it


def test_an_indexed_store_may_land_on_a_patched_operand_but_not_on_an_opcode(compiled_cache):
    """STY $C0A7 (a fixed patch: ADC's immediate is live); STA $C0A4,X; ADC #$00; RTS. The indexed
    store lands on $C0A4 + X: X = 3, the live immediate (compiled: A = 2 A + C); X = 0, 1, 2, 4: the
    STA's own operand, ADC's opcode, RTS (left to the batched core, which agrees); X = $10: past the
    code (compiled: A = A + Y + C)."""
    code = bytes([0x8C, 0xA7, 0xC0, 0x9D, 0xA4, 0xC0, 0x69, 0x00, 0x60])
    registers, memory = random_states(33, LANES)
    xs = np.array([3, 0, 1, 2, 4, 0x10])
    registers[:, 1] = xs[np.arange(LANES) % len(xs)]
    registers[:, 3] = 0x20 | (registers[:, 3] & 1)
    compiled, left = _three_engines("6510", code, registers, memory)
    a, x, y, c = registers[:, 0], registers[:, 1], registers[:, 2], registers[:, 3] & 1
    fell = [r == "fallback" for r in compiled]
    assert fell == np.isin(x, [0, 1, 2, 4]).tolist() and left == sum(fell)
    ran = [i for i in range(LANES) if not fell[i]]
    assert [compiled[i][0] for i in ran] == [int((a[i] + (a[i] if x[i] == 3 else y[i]) + c[i]) & 255) for i in ran]


def test_a_patched_jmp_goes_through_the_dispatch(compiled_cache):
    """STX $C0A8 (JMP's low byte); BEQ $C0AA; BCC $C0AA; JMP $C0B0 (patched); $C0AA: LDA #2; RTS; NOP x3;
    $C0B0: LDA #3; RTS. With Z and C clear the JMP goes where X says: $B0 and $AA start blocks (both
    dispatched: $C0AA has two ways in), compiled; $AD (a NOP inside a block) is left to the batched core."""
    code = bytes([0x8E, 0xA8, 0xC0, 0xF0, 0x05, 0x90, 0x03, 0x4C, 0xB0, 0xC0, 0xA9, 0x02, 0x60,
                  0xEA, 0xEA, 0xEA, 0xA9, 0x03, 0x60])
    registers, memory = random_states(34, LANES)
    xs = np.array([0xB0, 0xAA, 0xAD])
    registers[:, 1] = xs[np.arange(LANES) % len(xs)]
    registers[:, 3] = np.where(np.arange(LANES) % 7 == 0, 0x22, 0x21)  # Z set now and then: BEQ to $C0AA
    compiled, left = _three_engines("6510", code, registers, memory)
    x, z = registers[:, 1], registers[:, 3] == 0x22
    fell = [r == "fallback" for r in compiled]
    assert fell == ((x == 0xAD) & ~z).tolist() and left == sum(fell)
    assert [r[0] for r in compiled if r != "fallback"] == [3 if x[i] == 0xB0 and not z[i] else 2
                                                          for i in range(LANES) if not fell[i]]


@pytest.mark.parametrize("cpu", ["6510", "65c02"])
def test_a_patched_jmp_indirect_reads_its_pointer_where_the_patch_says(cpu, compiled_cache):
    """BCS $C0A5; LDA #2; RTS; $C0A5: CLC; STX $C0AA (JMP's pointer low byte); JMP ($0300) (patched to
    ($03xx)), carry set on entry. The pointer at $0310 is $C0A0 (the entry: carry now clear, A = 2; by
    hand 3 + 2 + 4 + 5 + 2 + 2 + 6 = 24 cycles on the 6510, 25 on the 65C02, whose JMP (ind) takes 6);
    at $03FF the NMOS takes the high byte from $0300 ($C0: the entry again), the 65C02 from $0400 ($00:
    no block, left to the batched core); at $0320, $C0AA: inside an instruction, left."""
    code = bytes([0xB0, 0x03, 0xA9, 0x02, 0x60, 0x18, 0x8E, 0xAA, 0xC0, 0x6C, 0x00, 0x03])
    registers, memory = random_states(35, 30)
    xs = np.array([0x10, 0xFF, 0x20])
    registers[:, 1] = xs[np.arange(30) % len(xs)]
    registers[:, 3] = 0x21
    for address, byte in ((0x0310, 0xA0), (0x0311, 0xC0), (0x03FF, 0xA0), (0x0300, 0xC0), (0x0400, 0x00),
                          (0x0320, 0xAA), (0x0321, 0xC0)):
        memory[:, len(ZERO_PAGE) + address - DATA.start] = byte
    compiled, left = _three_engines(cpu, code, registers, memory)
    x = registers[:, 1]
    fell = [r == "fallback" for r in compiled]
    assert fell == ((x == 0x20) | ((x == 0xFF) & (cpu == "65c02"))).tolist() and left == sum(fell)
    assert {(r[0], r[4]) for r in compiled if r != "fallback"} == {(2, 24 if cpu == "6510" else 25)}


def test_many_known_lane_and_output_addresses_are_looped_over(compiled_cache):
    """1,500 known lane addresses and 1,500 known output addresses: above LINES_LIMIT the function loops
    over the arrays a run passes (numba took minutes over hundreds of lines, one per address), so the
    source does not grow with them; LDA $2000+k; STA $3000 copies one lane byte to the first output."""
    from retro.cpu.translate import LINES_LIMIT

    lanes = tuple(range(0x2000, 0x2000 + 1500))
    outputs = tuple(range(0x3000, 0x3000 + 1500))
    code = bytes([0xAD, 0xDB, 0x25, 0x8D, 0x00, 0x30, 0x60])  # LDA $25DB (the last lane byte); STA $3000; RTS
    image = image_with(code)
    sp = push_return_trap(image)
    sizes = {count: len(translate(image.__getitem__, CODE, "6510", RETURN_TRAP, lanes=lanes[:count],
                                  outputs=outputs[:count]).source) for count in (LINES_LIMIT + 1, len(lanes))}
    assert sizes[LINES_LIMIT + 1] == sizes[len(lanes)]
    routine = compile_routine(bytes(image), CODE, "6510", RETURN_TRAP, lanes=lanes, outputs=outputs)
    n = 50
    lane_bytes = np.random.default_rng(8).integers(0, 256, size=(len(lanes), n)).astype(np.uint8)
    done = routine.run(bytes(image), (), np.asarray([0, 0, 0, 0x20], dtype=np.int64), sp, BUDGET, RETURN_TRAP,
                       CALL_STACK_TOP, np.asarray(outputs, dtype=np.int64), np.asarray(lanes, dtype=np.int64), lane_bytes)
    assert done["status"].tolist() == [0] * n and done["a"].tolist() == lane_bytes[-1].tolist()
    assert done["bytes"][0].tolist() == lane_bytes[-1].tolist() and not done["bytes"][1:].any()
    assert done["cycles"].tolist() == [4 + 4 + 6] * n


def test_a_call_writing_more_than_the_log_holds_leaves_memory_as_the_image(compiled_cache):
    """LDY $0480; LDX #0; loop: STA $0400,X; STA $0401,X; INX; BNE loop; INY; BNE loop; RTS: 256 x 256 x 2 =
    131,072 writes to computed addresses when $0480 holds 0 (the image's), twice the write log's 65,536,
    so the call's writes are undone by copying the whole image back. The second call must find $0480 as
    the image has it, not as the first call left it ($77: 137 outer rounds). By hand: 4 + 2 + 256 x (256 x
    (5 + 5 + 2 + 3) - 1 + 2 + 3) - 1 + 6 = 984,075 cycles for each call."""
    code = bytes([0xAC, 0x80, 0x04, 0xA2, 0x00, 0x9D, 0x00, 0x04, 0x9D, 0x01, 0x04, 0xE8, 0xD0, 0xF7,
                  0xC8, 0xD0, 0xF4, 0x60])
    image = image_with(code)
    sp = push_return_trap(image)
    routine = compile_routine(bytes(image), CODE, "6510", RETURN_TRAP, columns=1, sets=((0, 0, SET_A),))
    done = routine.run(bytes(image), (np.array([0x77, 0x55], dtype=np.int64),), np.asarray([0, 0, 0, 0x20]), sp,
                       10_000_000, RETURN_TRAP, CALL_STACK_TOP, np.asarray([0x0480], dtype=np.int64))
    assert done["status"].tolist() == [0, 0]
    assert done["bytes"][0].tolist() == [0x77, 0x55]
    assert done["cycles"].tolist() == [984_075, 984_075]
    assert bytes(routine.memory_for(bytes(image))[1].astype(np.uint8)) == bytes(image)  # the run left the image


def test_many_returns_share_the_return_arm_and_agree_on_all_three_engines(compiled_cache):
    """JSR sub; ADC #1; JSR sub; RTS, and sub a ladder of CMP #k; BCS +1; RTS (six exits) ending in LDA #0;
    RTS: eight RTSs (RETURN_ARM_FROM or more), so every RTS written (some rungs are if-converted
    together) goes through the dispatch's one return arm (JSR pushes: not `direct`); every call agrees with the batched core and Machine."""
    ladder = b"".join(bytes([0xC9, k, 0xB0, 0x01, 0x60]) for k in (0x20, 0x40, 0x60, 0x80, 0xA0, 0xC0))
    sub = CODE + 9
    code = bytes([0x20, sub & 0xFF, sub >> 8, 0x69, 0x01, 0x20, sub & 0xFF, sub >> 8, 0x60]) + ladder + bytes([0xA9, 0x00, 0x60])
    image = image_with(code)
    push_return_trap(image)
    source = translate(image.__getitem__, CODE, "6510", RETURN_TRAP).source
    assert source.count("# the return arm") >= 2 and "RTS: the return address from the stack" in source
    compiled, left = _three_engines("6510", code, *random_states(40, LANES))
    assert left == 0 and None not in compiled
    assert len({r[4] for r in compiled}) > 4  # the calls leave the ladder at different rungs
