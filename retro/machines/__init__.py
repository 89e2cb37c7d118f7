"""Machines put together from the CPU and chips, with no more hardware than a scene needs.

`build_machine` is the way in: a scene says what is in the chips and where the beam starts; the
machine modules (`c64`, `nes`) are where the chips are put on the bus.
"""

from __future__ import annotations

from retro.cpu.machine import Machine
from retro.errors import InputError
from retro.machines.c64 import build_c64
from retro.machines.nes import build_nes
from retro.scenes.nes import NesScene
from retro.scenes.vic import VicScene

DEFAULT_CPU = "6510"
# The machines a routine can be shown on, by name, with their CPU; "none" is a bare CPU (code from
# another 6502 computer: an Atari 2600, a VIC-20, a Commander X16): no C64 or NES raster figures.
MACHINE_CPUS = {"c64": "6510", "nes": "2a03"}
BARE = "none"
MACHINES = (*MACHINE_CPUS, BARE)


def machine_for(cpu: str) -> str:
    """The machine a CPU implies when none is named: the C64 for the 6510, the NES for the 2A03,
    no machine for any other (the 65C02)."""
    return next((name for name, its_cpu in MACHINE_CPUS.items() if its_cpu == cpu), BARE)


def build_machine(scene: VicScene | NesScene | None = None, *, cpu: str | None = None) -> Machine:
    """A fresh Machine: a C64 for a VicScene, a NES for a NesScene, a bare CPU of variant `cpu`
    (default "6510") without a scene. With a scene, `cpu` (if given) must be the scene's."""
    if scene is None:
        return Machine(cpu or DEFAULT_CPU)
    if cpu is not None and cpu != scene.cpu_variant:
        raise InputError(f"{scene.source}: a scene for the {scene.cpu_variant.upper()}, not the {cpu.upper()}")
    if isinstance(scene, VicScene):
        return build_c64(scene.state, start_line=scene.start_line, start_cycle=scene.start_cycle,
                         irq_vector=scene.irq_vector)
    if isinstance(scene, NesScene):
        return build_nes(scene.ppu_state())
    raise TypeError(f"build_machine: not a scene: {type(scene).__name__}")
