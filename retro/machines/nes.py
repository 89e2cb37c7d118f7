"""A NES as far as timing needs one: the 2A03 and the PPU, with OAM DMA at $4014.

`build_nes` is the one place a NES is put together; an NES scene only says what the PPU holds
(`retro.machines.build_machine` reads it). No APU, controllers or mapper: the program runs from RAM.
"""

from __future__ import annotations

from retro.chips.ppu.constants import OAMDMA, PPU_REGISTER_BASE, PPU_REGISTER_END
from retro.chips.ppu.device import PpuDevice
from retro.chips.ppu.state import PpuState
from retro.cpu.machine import Machine

CPU = "2a03"


def build_nes(state: PpuState | None = None) -> Machine:
    """A fresh NES: a 2A03 with a PPU holding `state` (power-on state without one) at $2000-$3FFF
    (8-byte mirrors) and $4014, its clock at line 0, dot 0 now."""
    machine = Machine(CPU)
    # OAM DMA copies a page of the CPU's memory and holds the CPU meanwhile: the PPU needs both
    device = PpuDevice(state, read_memory=machine.bus.peek, stall=machine.mpu.stall)
    device.start_clock(machine.cycle)
    machine.attach(device, PPU_REGISTER_BASE, PPU_REGISTER_END)
    machine.attach(device, OAMDMA, OAMDMA)
    return machine


def ppu_of(machine: Machine) -> PpuDevice | None:
    """The machine's PPU, or None on a machine without one."""
    device = machine.mpu.lines
    return device if isinstance(device, PpuDevice) else None
