"""`retro demo`: the toolkit's main job on built-in examples, each capability one step.

A step is a function `step(out_dir: Path) -> list[str]` returning the lines to print; any files it
writes go into out_dir. Steps are listed in DEMO_STEPS by dotted path so a step's module is only
imported when the demo runs.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from pathlib import Path

from retro.fileio import output_folder

# (title, "module:function")
DEMO_STEPS: list[tuple[str, str]] = [
    ("Assemble and run a 6502 routine", "retro.demo.cpu:assemble_and_run"),
    ("VIC-II collision scene: $D01E/$D01F/$D019 and the overlap image", "retro.demo.vic:latch_scene"),
    ("Parry pipeline: padded AABB window, SAT contact, MTV knock-back", "retro.demo.parry:parry_sequence"),
    ("NES sprite-zero hit: model, picture, polling loop", "retro.demo.nes:sprite_zero"),
    ("Collision routines: cross-checked results and cycles", "retro.demo.routines:cycles_table"),
    ("Speed against accuracy: cycles and error rates of every collision method", "retro.demo.study:chart_step"),
]


def run_demo(out_dir: Path, emit: Callable[[str], None] = print) -> Path:
    output_folder(out_dir)
    for title, target in DEMO_STEPS:
        module_name, func_name = target.split(":")
        step = getattr(importlib.import_module(module_name), func_name)
        emit(f"== {title}")
        for line in step(out_dir):
            emit(f"   {line}")
    emit(f"Output files are in {out_dir.resolve()}")
    return out_dir
