"""`retro demo`: the toolkit's main job on built-in examples, each capability one step.

A step is a function `step(out_dir: Path) -> list[str]` returning the lines to print; any files it
writes go into out_dir. `demo_steps()` imports the steps when the demo runs (not when the CLI starts).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from retro.fileio import output_folder


def demo_steps() -> list[tuple[str, Callable[[Path], list[str]]]]:
    """(title, step) in the order the demo runs them."""
    from retro.demo import cpu, nes, parry, routines, study, vic

    return [
        ("Assemble and run a 6502 routine", cpu.assemble_and_run),
        ("VIC-II collision scene: $D01E/$D01F/$D019 and the overlap image", vic.latch_scene),
        ("Parry pipeline: padded AABB window, SAT contact, MTV knock-back", parry.parry_sequence),
        ("NES sprite-zero hit: model, picture, polling loop", nes.sprite_zero),
        ("Collision routines: cross-checked results and cycles", routines.cycles_table),
        ("Speed against accuracy: cycles and error rates of every collision method", study.chart_step),
    ]


def run_demo(out_dir: Path, emit: Callable[[str], None] = print) -> Path:
    output_folder(out_dir)
    for title, step in demo_steps():
        emit(f"== {title}")
        for line in step(out_dir):
            emit(f"   {line}")
    emit(f"Output files are in {out_dir.resolve()}")
    return out_dir
