"""Load a program (source, PRG, raw binary or iNES image) into a machine, optionally with a chip
scene attached, and call a routine.

This is what `retro run` does, as a function returning plain data: the CLI only parses and prints.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from retro.cpu.machine import DEFAULT_BUDGET, DEFAULT_FLAGS, CallResult, Machine
from retro.cpu.mpu import FLAG_C, FLAG_D, FLAG_I, FLAG_N, FLAG_V, FLAG_Z
from retro.errors import InputError
from retro.loaders import load_program
from retro.numbers import parse_int
from retro.program import Program

DEFAULT_VARIANT = "6510"
# the status flags a caller may set for the call (B and bit 5 are not flags the CPU keeps)
SETTABLE_FLAGS = {"n": FLAG_N, "v": FLAG_V, "d": FLAG_D, "i": FLAG_I, "z": FLAG_Z, "c": FLAG_C}


@dataclass
class RunReport:
    program: Program
    entry: int
    result: CallResult
    peeks: dict[str, list[int]]  # TARGET as the user gave it (without :N) -> byte values
    machine: Machine


def status_with_flags(flags: dict[str, int] | None) -> int:
    """The P register to enter with: the default, with each named flag (n v d i z c) set to 0 or 1."""
    p = DEFAULT_FLAGS
    for name, value in (flags or {}).items():
        bit = SETTABLE_FLAGS.get(name.lower())
        if bit is None:
            raise InputError(f"--{name}: not a settable flag (known: {', '.join(SETTABLE_FLAGS)})")
        if value not in (0, 1):
            raise InputError(f"--{name}: a flag is 0 or 1, got {value!r}")
        p = p | bit if value else p & ~bit
    return p


def _is_label(target: str) -> bool:
    """Whether --entry names a label rather than giving a number."""
    try:
        parse_int(target)
    except InputError:
        return True
    return False


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


def run_routine(path: str | Path, entry: str, *, labels: str | Path | None = None, load: int | str | None = None,
                a: int = 0, x: int = 0, y: int = 0, flags: dict[str, int] | None = None, sets: list[str] = (),
                peeks: list[str] = (), budget: int = DEFAULT_BUDGET, scene: str | Path | None = None,
                trace: bool = False) -> RunReport:
    program = load_program(path, symbols=labels, load=load)
    from_binary_without_symbols = labels is None and not program.listing
    if from_binary_without_symbols and _is_label(str(entry)) and str(entry).strip() not in program.symbols:
        raise InputError(f"{path} has no symbols: pass --labels with the symbol file your assembler wrote, "
                         f"or give --entry as an address")
    variant = program.cpu or DEFAULT_VARIANT
    loaded_scene = None
    if scene is not None:
        from retro.scenes import load_scene
        loaded_scene = load_scene(scene)
        if program.cpu and loaded_scene.cpu_variant != program.cpu:
            raise InputError(f"--scene {scene}: a scene for the {loaded_scene.cpu_variant.upper()}, "
                             f"but {path} is a program for the {program.cpu.upper()}")
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
    result = machine.call(entry_address, a=a, x=x, y=y, p=status_with_flags(flags), memory=memory, budget=budget,
                          trace=trace)
    values = {target: machine.peek(target, count) for target, count in peek_counts.items()}
    return RunReport(program=program, entry=entry_address, result=result, peeks=values, machine=machine)
