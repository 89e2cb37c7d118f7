"""The SingleStepTests vectors (../shared/cpu-vectors): loading, the erratum fix-up and comparison,
shared by the scalar and the batched core's vector tests (see test_vectors.py for the erratum)."""

from __future__ import annotations

import gzip
import json
from collections.abc import Iterator
from pathlib import Path

from retro.cpu.bus import Bus

# Facts from 64doc / No More Secrets, written here independently of retro.cpu.mpu.
JAM = {0x02, 0x12, 0x22, 0x32, 0x42, 0x52, 0x62, 0x72, 0x92, 0xB2, 0xD2, 0xF2}
UNSTABLE = {0x93: "SHA", 0x9F: "SHA", 0x9E: "SHX", 0x9C: "SHY", 0x9B: "TAS", 0xBB: "LAS", 0x8B: "ANE",
            0xAB: "LXA"}
SUPPORTED = sorted(set(range(256)) - JAM - set(UNSTABLE))
NOP_ABS = 0x0C
NOP_ABS_X = {0x1C, 0x3C, 0x5C, 0x7C, 0xDC, 0xFC}
PUSHES_P = {0x00, 0x08}  # BRK, PHP
FLAG_D = 0x08
REAL_FLAGS = 0xCF  # P without bits 5 and 4 (B), which exist only in pushed copies


def load(directory: Path, opcode: int) -> list[dict]:
    path = directory / f"{opcode:02x}.json.gz"
    assert path.exists(), f"{path}: vectors of a supported opcode are missing"
    with gzip.open(path, "rt") as fh:
        return json.load(fh)


def operand_word(vector: dict) -> int:
    ram = dict(vector["initial"]["ram"])
    pc = vector["initial"]["pc"]
    return ram[(pc + 1) & 0xFFFF] | ram[(pc + 2) & 0xFFFF] << 8


def nop_effective_address(opcode: int, vector: dict) -> int:
    base = operand_word(vector)
    return base if opcode == NOP_ABS else (base + vector["initial"]["x"]) & 0xFFFF


def expected_cycles(opcode: int, vector: dict) -> int:
    """The vector's cycle count, with the final read it omits for the NOPs above put back."""
    cycles = vector["cycles"]
    if opcode != NOP_ABS and opcode not in NOP_ABS_X:
        return len(cycles)
    last_address, _, last_kind = cycles[-1]
    has_final_read = last_kind == "read" and last_address == nop_effective_address(opcode, vector)
    return len(cycles) + (0 if has_final_read else 1)


def differences(state: dict, expected: dict, cycles: int | None) -> list[str]:
    """What differs between a run's state and an expected final state (cycles None: not compared)."""
    found = [f"{key} {state[key]} != {expected[key]}" for key in ("pc", "s", "a", "x", "y") if state[key] != expected[key]]
    if (state["p"] ^ expected["p"]) & REAL_FLAGS:
        found.append(f"p ${state['p']:02X} != ${expected['p']:02X}")
    want = dict(expected["ram"])
    found += [f"ram ${a:04X} {v} != {want[a]}" for a, v in state["ram"] if v != want[a]]
    if cycles is not None and state["cycles"] != cycles:
        found.append(f"cycles {state['cycles']} != {cycles}")
    return found


def all_vectors(directory: Path) -> Iterator[tuple[int, dict]]:
    for opcode in SUPPORTED:
        for vector in load(directory, opcode):
            yield opcode, vector


class Harness:
    """One MPU on one 64 KiB memory, reused: each vector's bytes are cleared after it runs."""

    def __init__(self, cpu_class):
        self.bus = Bus()
        self.memory = self.bus.memory
        self.mpu = cpu_class(memory=self.memory, page_devices=self.bus.page_devices)

    def run(self, vector: dict, p: int | None = None) -> dict:
        initial = vector["initial"]
        for address, value in initial["ram"]:
            self.memory[address] = value
        mpu = self.mpu
        mpu.pc, mpu.sp, mpu.a, mpu.x, mpu.y = initial["pc"], initial["s"], initial["a"], initial["x"], initial["y"]
        mpu.p = initial["p"] if p is None else p
        start = mpu.processorCycles
        try:
            mpu.step()
            state = {"pc": mpu.pc, "s": mpu.sp, "a": mpu.a, "x": mpu.x, "y": mpu.y, "p": mpu.p,
                     "ram": [[address, self.memory[address]] for address, _ in vector["final"]["ram"]],
                     "cycles": mpu.processorCycles - start}
        finally:
            for address, _ in initial["ram"] + vector["final"]["ram"]:
                self.memory[address] = 0
        return state


def binary_expectation(reference: Harness, opcode: int, vector: dict) -> dict:
    """What a 6502 without decimal mode does: the 6510 run with D clear, then D as the vector ends.

    The final D never depends on arithmetic (only SED, CLD, PLP and RTI change it), so it is taken
    from the vector. BRK and PHP do no arithmetic and push D, so for them the vector itself holds."""
    if opcode in PUSHES_P:
        return vector["final"]
    state = reference.run(vector, p=vector["initial"]["p"] & ~FLAG_D)
    return {**state, "p": state["p"] & ~FLAG_D | vector["final"]["p"] & FLAG_D}
