"""The compiled engine (retro.cpu.translate + retro.cpu.compiled) against the SingleStepTests vectors
(../shared/cpu-vectors, or $RETRO_CPU_VECTORS) on the 6510 and the 2A03.

Each vector is a routine of one instruction: its initial RAM is the memory image, its PC the entry,
and its final PC the return address (so the translator finds the instruction, and for a branch, JMP,
JSR or RTS the way not taken as well). It runs through `compile_routine` and `CompiledRoutine.run`
as a check's calls do; registers, flags, every final RAM byte and the cycle count are compared with
the vector (on the 2A03, the 6510's binary result where D is set, as test_vectors.py explains). PC
and S are held by the return itself: the generated code stops only at the vector's final PC with the
vector's final S (anything else runs into other code or falls back, which fails the vector). A branch
or JMP to its own address (final PC = initial PC) runs twice against a budget of one instruction's
cycles plus one: it must stop on the budget having spent exactly twice the vector's cycles.

Two runs, as the translator folds each instruction's operands into its code (one numba compile per
vector: about 0.5 s of CPU each, far too many for 118,000 vectors):
- the generated source executed as Python (`python_function`: the very text numba compiles, with the
  same helpers of retro.cpu.compiled_ops): every vector with RETRO_EXHAUSTIVE=1, every 20th of each
  opcode otherwise;
- compiled by numba into a private cache (a real compile each): every supported opcode's first vector
  with D clear and first with D set with RETRO_EXHAUSTIVE=1; otherwise the first vector with D set of
  each opcode in NUMBA_SAMPLE, chosen to reach the translator's rules.

What the engine leaves to the batched core by design is counted apart and must be for its reason:
BRK and RTI stop (FALLBACK_STOP); a vector that writes into a byte the translator took as code falls
back (FALLBACK_WRITE) or is refused as self-modifying (Untranslatable). docs/compiled.md gives the counts.
"""

from __future__ import annotations

import os
from collections import Counter
from unittest import mock

import numpy as np
import pytest
from vectors import FLAG_D, SUPPORTED, Harness, binary_expectation, differences, expected_cycles, load

from retro.cpu import compiled, compiled_ops, translate
from retro.cpu.compiled import compile_routine, numba_problem
from retro.cpu.mpu import MPU6510
from retro.cpu.translate import BUDGET, FALLBACK_STOP, FALLBACK_WRITE, RETURNED, Untranslatable

pytestmark = pytest.mark.skipif(numba_problem() is not None, reason=f"{numba_problem()}")

FULL = os.environ.get("RETRO_EXHAUSTIVE") == "1"
SOURCE_STRIDE = 1 if FULL else 20  # every vector, or every 20th of each opcode (25 of 500)
STOPPING = {0x00: "BRK", 0x40: "RTI"}  # left to the batched core (docs/compiled.md)
SELF_LOOPS = {0x10, 0x30, 0x50, 0x70, 0x90, 0xB0, 0xD0, 0xF0, 0x4C, 0x6C}  # may return to their own address
NOWHERE = 0x10000  # a return address no 16-bit PC equals
BUDGET_CYCLES = 100  # far above any one instruction
# The bounded numba sample (one vector with D set each): a page-penalised read (abs,X; (zp),Y), a store
# and a read-modify-write by abs,X, a branch, JMP (ind), JSR, RTS, PHP and PLP, ADC and SBC, ARR, and the
# undocumented RRA, ISC, SBX, LAX and a NOP that reads.
NUMBA_SAMPLE = (0xBD, 0xB1, 0x9D, 0x1E, 0xD0, 0x6C, 0x20, 0x60, 0x08, 0x28, 0x69, 0xF1, 0x6B, 0x63, 0xE3, 0xCB,
                0xA7, 0x1C)


def python_function(translation, columns):
    """compiled._function's stand-in: the generated source executed by Python, not compiled."""
    namespace = {"np": np, **{name: getattr(compiled_ops, name) for name in compiled_ops.HELPERS}}
    exec(compile(translation.source, "<translated>", "exec"), namespace)  # noqa: S102 - the translator's own text
    return namespace[translation.function_name], 0.0, False


def image_of(vector: dict) -> bytes:
    memory = bytearray(0x10000)
    for address, value in vector["initial"]["ram"]:
        memory[address] = value
    return bytes(memory)


def writes_into(vector: dict, addresses) -> bool:
    return any(kind == "write" and address in addresses for address, _, kind in vector["cycles"])


def run_vector(cpu: str, opcode: int, vector: dict, expected: dict) -> tuple[str, list[str]]:
    """(outcome, differences): outcome "match", "differs", or why the batched core runs it instead."""
    initial, cycles = vector["initial"], expected_cycles(opcode, vector)
    image = image_of(vector)
    loops = expected["pc"] == initial["pc"]
    if loops and opcode not in SELF_LOOPS:
        return "differs", [f"returns to its own address ${initial['pc']:04X}: not provided for"]
    return_pc, budget = (NOWHERE, cycles + 1) if loops else (expected["pc"], BUDGET_CYCLES)
    try:
        routine = compile_routine(image, initial["pc"], cpu, return_pc,
                                  decimal_entry=bool(initial["p"] & FLAG_D))
    except Untranslatable as refused:
        own_bytes = {(initial["pc"] + k) & 0xFFFF for k in range(3)}
        if writes_into(vector, own_bytes):
            return "self-modifying", []
        return "differs", [f"refused: {refused}"]
    out_addr = np.array([address for address, _ in expected["ram"]], dtype=np.int64)
    base = np.array([initial[k] for k in ("a", "x", "y", "p")], dtype=np.int64)
    result = routine.run(image, (np.zeros(1, dtype=np.int64),), base, initial["s"], budget, return_pc,
                         expected["s"], out_addr)
    status = int(result["status"][0])
    if status == FALLBACK_STOP and opcode in STOPPING:
        return "stops", []
    if status == FALLBACK_WRITE and writes_into(vector, routine.translation.code_bytes):
        return "writes-code", []
    wanted_status, wanted_cycles = (BUDGET, 2 * cycles) if loops else (RETURNED, cycles)
    state = {"pc": expected["pc"], "s": expected["s"], **{k: int(result[k][0]) for k in ("a", "x", "y", "p")},
             "ram": [[address, int(value)] for address, value in zip(out_addr.tolist(), result["bytes"][:, 0])],
             "cycles": int(result["cycles"][0])}
    found = differences(state, expected, wanted_cycles)
    if status != wanted_status:
        found.append(f"status {status} != {wanted_status}")
    return ("differs" if found else "match"), found


def expectations(cpu: str, reference: Harness, opcode: int, vectors: list[dict]) -> list[dict]:
    """The vector's final state; on the 2A03 with D set, the 6510's binary result (test_vectors.py)."""
    if cpu == "6510":
        return [v["final"] for v in vectors]
    return [binary_expectation(reference, opcode, v) if v["initial"]["p"] & FLAG_D else v["final"] for v in vectors]


def run_all(cpu: str, chosen: dict[int, list[dict]]) -> tuple[Counter, list[str]]:
    reference = Harness(MPU6510)
    outcomes: Counter = Counter()
    failures: list[str] = []
    for opcode, vectors in chosen.items():
        for vector, expected in zip(vectors, expectations(cpu, reference, opcode, vectors)):
            outcome, found = run_vector(cpu, opcode, vector, expected)
            outcomes[outcome] += 1
            if found:
                failures.append(f"{cpu} ${opcode:02X} {vector['name']} (D={vector['initial']['p'] >> 3 & 1}): "
                                f"{'; '.join(found)}")
    return outcomes, failures


def summary(outcomes: Counter) -> str:
    return ", ".join(f"{count} {outcome}" for outcome, count in sorted(outcomes.items()))


def assert_honest(outcomes: Counter, failures: list[str], chosen: dict[int, list[dict]]) -> None:
    assert not failures, f"{len(failures)} vectors differ, first: {failures[:5]}"
    total = sum(len(v) for v in chosen.values())
    assert outcomes["match"] + outcomes["stops"] + outcomes["writes-code"] + outcomes["self-modifying"] == total
    stopping = sum(len(v) for opcode, v in chosen.items() if opcode in STOPPING)
    assert outcomes["stops"] == stopping
    assert outcomes["writes-code"] + outcomes["self-modifying"] <= total // 100, "too many fall back to check much"


@pytest.mark.parametrize("cpu", ["6510", "2a03"])
def test_generated_source_runs_every_vector_exactly(vector_dir, figures, cpu):
    chosen = {opcode: load(vector_dir, opcode)[::SOURCE_STRIDE] for opcode in SUPPORTED}
    with mock.patch.object(compiled, "_function", python_function):
        outcomes, failures = run_all(cpu, chosen)
    assert_honest(outcomes, failures, chosen)
    figures[f"compiled-source-{cpu}"] = (f"CPU vectors, compiled engine's generated source as Python, {cpu}: "
                                         f"{summary(outcomes)} ({'every vector' if FULL else 'every 20th'} "
                                         f"of {len(SUPPORTED)} opcodes)")


NUMBA_D = (False, True) if FULL else (True,)


def numba_sample(vector_dir) -> dict[int, list[dict]]:
    """Every opcode's first vector with D clear and first with D set with RETRO_EXHAUSTIVE=1; otherwise
    the first with D set of each NUMBA_SAMPLE opcode (where the 6510 and the 2A03 differ)."""
    chosen = {}
    for opcode in SUPPORTED if FULL else NUMBA_SAMPLE:
        vectors = load(vector_dir, opcode)
        chosen[opcode] = [next(v for v in vectors if bool(v["initial"]["p"] & FLAG_D) == d) for d in NUMBA_D]
    return chosen


@pytest.mark.parametrize("cpu", ["6510", "2a03"])
def test_numba_compiles_a_sample_of_vectors_exactly(vector_dir, figures, cpu, tmp_path, monkeypatch):
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path))  # a real compile every time, not a load
    chosen = numba_sample(vector_dir)
    outcomes, failures = run_all(cpu, chosen)
    assert_honest(outcomes, failures, chosen)
    assert any(tmp_path.rglob("*.nbc")), "nothing was compiled by numba"
    figures[f"compiled-numba-{cpu}"] = (f"CPU vectors, compiled engine (numba), {cpu}: {summary(outcomes)} "
                                        f"({len(chosen)} opcodes, {' and '.join('D set' if d else 'D clear' for d in NUMBA_D)} "
                                        f"one vector each)")

