"""Load a source or PRG into a machine (optionally with a chip scene attached) and call a routine.

This is what `retro run` does, as a function: the CLI only parses and prints.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.assembler import assemble_file
from retro.cpu.machine import DEFAULT_BUDGET, CallResult, Machine
from retro.errors import InputError
from retro.numbers import parse_int
from retro.program import Program, load_prg_file


@dataclass
class RunReport:
    program: Program
    entry: int
    result: CallResult
    peeks: dict[str, list[int]]  # TARGET as the user gave it (without :N) -> byte values
    machine: Machine


def load_program(path: str | Path, labels: str | Path | None = None) -> Program:
    if str(path).lower().endswith(".prg"):
        return load_prg_file(path, labels)
    if labels:
        raise InputError(f"{labels}: --labels goes with a .prg file; a source's labels come from the assembler")
    return assemble_file(path)


def parse_assignment(text: str) -> tuple[str, list[int]]:
    """'TARGET=V' or 'TARGET=V,V,...' -> (target, bytes)."""
    target, sep, values = text.partition("=")
    if not sep or not target.strip() or not values.strip():
        raise InputError(f"--set {text!r}: expected TARGET=VALUE[,VALUE...]")
    return target.strip(), [parse_int(v, field=f"--set {target.strip()}", lo=0, hi=0xFF) for v in values.split(",")]


def parse_peek(text: str) -> tuple[str, int]:
    """'TARGET' or 'TARGET:N' -> (target, count)."""
    target, sep, count = text.rpartition(":") if ":" in text else (text, "", "1")
    if not target.strip():
        raise InputError(f"--peek {text!r}: expected TARGET[:N]")
    return target.strip(), parse_int(count, field=f"--peek {text} count", lo=1, hi=0x10000)


def _peek_counts(peeks: list[str]) -> dict[str, int]:
    """--peek arguments -> {TARGET as given: byte count}; one count per target."""
    counts: dict[str, int] = {}
    for given in peeks:
        target, count = parse_peek(given)
        if counts.get(target, count) != count:
            raise InputError(f"--peek {given!r}: {target} is already peeked with count {counts[target]}")
        counts[target] = count
    return counts


def run_routine(path: str | Path, entry: str, *, labels: str | Path | None = None, a: int = 0, x: int = 0,
                y: int = 0, sets: list[str] = (), peeks: list[str] = (), budget: int = DEFAULT_BUDGET,
                scene: str | Path | None = None, trace: bool = False) -> RunReport:
    program = load_program(path, labels)
    variant = "6510"
    loaded_scene = None
    if scene is not None:
        from retro.scenes import load_scene
        loaded_scene = load_scene(scene)
        variant = loaded_scene.cpu_variant
    machine = Machine(variant)
    if loaded_scene is not None:
        loaded_scene.attach(machine)
    machine.load(program)
    memory = dict(parse_assignment(s) for s in sets)
    for target in memory:
        machine.resolve(target, f"--set {target}")
    peek_counts = _peek_counts(peeks)
    for target in peek_counts:
        machine.resolve(target, f"--peek {target}")
    entry_address = machine.resolve(entry, "--entry")
    result = machine.call(entry_address, a=a, x=x, y=y, memory=memory, budget=budget, trace=trace)
    values = {target: machine.peek(target, count) for target, count in peek_counts.items()}
    return RunReport(program=program, entry=entry_address, result=result, peeks=values, machine=machine)
