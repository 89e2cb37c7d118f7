"""The batched core (retro.cpu.batch) against the SingleStepTests vectors, each opcode's vectors as the
lanes of one batch: registers, flags, every final RAM byte and the cycle count, as for the scalar core
(test_vectors.py, which also explains the NOP erratum fix-up in `expected_cycles`)."""

from __future__ import annotations

import numpy as np
import pytest
from vectors import FLAG_D, JAM, PUSHES_P, REAL_FLAGS, SUPPORTED, UNSTABLE, expected_cycles, load

from retro.cpu.batch import BatchCpu, LaneError

REGISTERS = (("pc", "pc"), ("s", "sp"), ("a", "a"), ("x", "x"), ("y", "y"))


def run_batch(variant: str, vectors: list[dict], p_override=None) -> BatchCpu:
    """One batch: lane i starts from vector i's initial state and runs one instruction."""
    cpu = BatchCpu(variant, bytes(0x10000), len(vectors), stop_on_brk=False)
    lanes, addresses, values = [], [], []
    for lane, vector in enumerate(vectors):
        for address, value in vector["initial"]["ram"]:
            lanes.append(lane)
            addresses.append(address)
            values.append(value)
    cpu.memory.write(np.array(lanes), np.array(addresses), np.array(values))
    for key, attribute in REGISTERS:
        getattr(cpu, attribute)[:] = [v["initial"][key] for v in vectors]
    cpu.p[:] = [v["initial"]["p"] if p_override is None else p_override(v) for v in vectors]
    cpu.step()
    return cpu


def lane_differences(cpu: BatchCpu, opcode: int, vectors: list[dict], expected: list[dict]) -> list[str]:
    checked = [(lane, address, value) for lane, want in enumerate(expected) for address, value in want["ram"]]
    lanes, addresses, values = (np.array(column) for column in zip(*checked))
    got = cpu.memory.read(lanes, addresses)  # every final byte of every lane in one read
    wrong_bytes: dict[int, list[str]] = {}
    for lane, address, value, have in zip(lanes.tolist(), addresses.tolist(), values.tolist(), got.tolist()):
        if have != value:
            wrong_bytes.setdefault(lane, []).append(f"ram ${address:04X} {have} != {value}")
    found = []
    for lane, (vector, want) in enumerate(zip(vectors, expected)):
        problems = [f"{key} {int(getattr(cpu, attr)[lane])} != {want[key]}" for key, attr in REGISTERS
                    if int(getattr(cpu, attr)[lane]) != want[key]]
        if (int(cpu.p[lane]) ^ want["p"]) & REAL_FLAGS:
            problems.append(f"p ${int(cpu.p[lane]):02X} != ${want['p']:02X}")
        problems += wrong_bytes.get(lane, [])
        if int(cpu.cycles[lane]) != expected_cycles(opcode, vector):
            problems.append(f"cycles {int(cpu.cycles[lane])} != {expected_cycles(opcode, vector)}")
        if cpu.error[lane]:
            problems.append(f"stopped: {LaneError(int(cpu.error[lane])).name}")
        if problems:
            found.append(f"${opcode:02X} {vector['name']}: {'; '.join(problems)}")
    return found


def test_every_supported_vector_matches_as_lanes_on_the_6510(vector_dir, figures):
    failures: list[str] = []
    lanes = 0
    for opcode in SUPPORTED:
        vectors = load(vector_dir, opcode)
        cpu = run_batch("6510", vectors)
        failures += lane_differences(cpu, opcode, vectors, [v["final"] for v in vectors])
        lanes += len(vectors)
    assert not failures, f"{len(failures)} lanes differ, first: {failures[:5]}"
    figures["batch"] = f"CPU vectors, batched 6510: {lanes}/{lanes} lanes of {len(SUPPORTED)} opcodes match"


def test_2a03_lanes_stay_binary_with_d_set(vector_dir):
    """Run with D clear on the 6510 batch for the binary truth, then with D set on the 2A03 batch: every
    register, byte and cycle must equal the binary run (D itself as the vector ends)."""
    failures: list[str] = []
    decimal_vectors = 0
    for opcode in SUPPORTED:
        vectors = [v for v in load(vector_dir, opcode) if v["initial"]["p"] & FLAG_D]
        if not vectors or opcode in PUSHES_P:
            continue
        decimal_vectors += len(vectors)
        binary = run_batch("6510", vectors, lambda v: v["initial"]["p"] & ~FLAG_D)
        nes = run_batch("2a03", vectors)
        for lane, vector in enumerate(vectors):
            for _, attr in REGISTERS + (("cycles", "cycles"),):
                if getattr(binary, attr)[lane] != getattr(nes, attr)[lane]:
                    failures.append(f"${opcode:02X} {vector['name']}: {attr}")
            if (binary.p[lane] ^ nes.p[lane]) & REAL_FLAGS & ~FLAG_D:
                failures.append(f"${opcode:02X} {vector['name']}: p")
    assert decimal_vectors > 10_000
    assert not failures, f"{len(failures)} lanes differ, first: {failures[:5]}"


@pytest.mark.parametrize("opcode", sorted(JAM | set(UNSTABLE)))
def test_jam_and_unstable_opcodes_stop_their_lanes_only(opcode):
    image = bytearray(0x10000)
    image[0x1000] = opcode
    image[0x2000] = 0xEA  # NOP
    cpu = BatchCpu("6510", bytes(image), 2)
    cpu.pc[:] = [0x1000, 0x2000]
    cpu.step()
    assert LaneError(int(cpu.error[0])) == (LaneError.JAM if opcode in JAM else LaneError.UNSTABLE)
    assert int(cpu.error_pc[0]) == 0x1000
    assert cpu.error[1] == 0 and cpu.pc[1] == 0x2001 and cpu.cycles[1] == 2
