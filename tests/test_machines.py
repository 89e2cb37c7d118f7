"""build_machine: a C64 for a VIC-II scene, a NES for an NES scene, a bare CPU without one; the
scenes only configure (they import no machine), and the machines sit below the routines."""

from __future__ import annotations

import pytest
from test_layers import package_imports

from retro.chips.ppu.device import PpuDevice
from retro.chips.vic.device import VicDevice
from retro.cpu.mpu import MPU2A03, MPU6510
from retro.errors import InputError
from retro.machines import build_machine
from retro.machines.c64 import KERNAL_IRQ_ENTRY, vic_of
from retro.machines.nes import ppu_of
from retro.scenes import nes, vic


def vic_scene(**cpu) -> vic.VicScene:
    return vic.parse({"chip": "vic-ii", "video": "ntsc", "cpu": cpu}, "v.toml")


def nes_scene() -> nes.NesScene:
    return nes.parse({"chip": "nes", "ppu": {"ctrl": 0x80}, "oam": [{"y": 10, "tile": 1, "x": 20}]}, "n.toml")


def devices(machine) -> dict[tuple[int, int], object]:
    return {(start, end): device for start, end, device in machine.bus.devices}


def test_without_a_scene_a_bare_cpu():
    machine = build_machine()
    assert machine.variant == "6510" and isinstance(machine.mpu, MPU6510)
    assert machine.bus.devices == [] and machine.mpu.lines is None
    nes_cpu = build_machine(cpu="2a03")
    assert nes_cpu.variant == "2a03" and isinstance(nes_cpu.mpu, MPU2A03) and nes_cpu.bus.devices == []


def test_a_vic_scene_gives_a_c64():
    scene = vic_scene(start_line=200, start_cycle=65)
    machine = build_machine(scene)
    assert machine.variant == scene.cpu_variant == "6510" and isinstance(machine.mpu, MPU6510)
    device = vic_of(machine)
    assert isinstance(device, VicDevice) and devices(machine) == {(0xD000, 0xD3FF): device}
    assert machine.mpu.lines is device  # BA and IRQ come from the VIC-II
    assert device.video is scene.state.video and device.beam(machine.cycle)[1:] == (200, 65)
    assert machine.peek(0xFFFE, 2) == [0, 0]  # the CPU's own IRQ vector: nothing put in RAM
    assert ppu_of(machine) is None


def test_a_0314_scene_gets_the_kernal_irq_entry():
    machine = build_machine(vic_scene(irq_vector="$0314"))
    assert machine.peek(0xFFFE, 2) == [KERNAL_IRQ_ENTRY & 0xFF, KERNAL_IRQ_ENTRY >> 8]
    assert machine.peek(KERNAL_IRQ_ENTRY) == [0x48]  # PHA


def test_an_nes_scene_gives_a_nes():
    scene = nes_scene()
    machine = build_machine(scene)
    assert machine.variant == scene.cpu_variant == "2a03" and isinstance(machine.mpu, MPU2A03)
    device = ppu_of(machine)
    assert isinstance(device, PpuDevice)
    assert devices(machine) == {(0x2000, 0x3FFF): device, (0x4014, 0x4014): device}  # registers and OAM DMA
    assert machine.mpu.lines is device  # NMI comes from the PPU
    assert device.ctrl == 0x80 and bytes(device.oam[:4]) == bytes([10, 1, 0, 20])
    assert device.origin == machine.cycle and device.read_memory == machine.bus.peek
    assert vic_of(machine) is None


def test_each_build_is_a_fresh_machine():
    scene = nes_scene()
    assert build_machine(scene) is not build_machine(scene)
    assert ppu_of(build_machine(scene)) is not ppu_of(build_machine(scene))


def test_the_cpu_variant_is_a_field_of_both_scene_kinds():
    for kind in (vic.VicScene, nes.NesScene):
        assert "cpu_variant" in kind.__dataclass_fields__
    assert (vic_scene().cpu_variant, nes_scene().cpu_variant) == ("6510", "2a03")


def test_a_cpu_that_is_not_the_scenes_is_refused():
    assert build_machine(nes_scene(), cpu="2a03").variant == "2a03"
    with pytest.raises(InputError, match="n.toml: a scene for the 2A03, not the 6510"):
        build_machine(nes_scene(), cpu="6510")
    with pytest.raises(TypeError):
        build_machine("scene.toml")


def test_scenes_configure_and_machines_assemble():
    edges = package_imports()
    assert not edges["scenes"] & {"machines", "routines", "analysis"}, edges["scenes"]
    assert not edges["machines"] & {"routines", "analysis"}, edges["machines"]
    assert {"scenes", "chips", "cpu"} <= edges["machines"]
