"""Emulated CPU speed: bare py65 against retro's Machine, side by side in one run.

The same 6502 loop (LDA abs,X / CLC / ADC # / STA abs,X / INX / BNE, about 1 M cycles) runs on:
  1. bare py65: py65.devices.mpu6502.MPU on a plain list, driven by `while pc != stop: step()`;
  2. retro Machine.call, plain RAM;
  3. retro Machine.call with a device mapped at $D000-$D3FF that the loop does not touch;
and a second loop that also reads the device ($D012) every iteration runs on bare py65 (plain RAM
there) and on the Machine with the device. Each configuration runs ROUNDS times, interleaved; the
best round counts (the least disturbed by other processes). Goal: case 3 >= 0.85x case 1.

    python benchmarks/cpu_speed.py [--rounds N]
"""

from __future__ import annotations

import argparse
import time

from py65.devices.mpu6502 import MPU as BarePy65

from retro.assembler import assemble_text
from retro.cpu import Machine

DEVICE_START, DEVICE_END = 0xD000, 0xD3FF
RETURN_ADDRESS = 0xFFFF  # bare py65: RTS to $0000 ends the run
OUTER_ROUNDS = 230  # Y: about 1 M cycles per run

LOOP = """
.org $c000
entry:  ldy #{outer}
outer:  ldx #0
inner:  lda table,x
{device_read}        clc
        adc #1
        sta buffer,x
        inx
        bne inner
        dey
        bne outer
        rts
.advance $c100
table:  .advance $c200
buffer: .advance $c300
"""


class RasterRegister:
    """A minimal device: reads return a counter, as a chip register would; no other work."""

    def __init__(self) -> None:
        self.reads = 0

    def read(self, address: int, cycle: int) -> int:
        self.reads += 1
        return cycle & 0xFF

    def write(self, address: int, value: int, cycle: int) -> None:
        pass

    def peek(self, address: int) -> int:
        return 0


def bare_py65(program) -> tuple[int, float]:
    memory = [0] * 0x10000
    memory[program.origin:program.end] = list(program.code)
    mpu = BarePy65(memory=memory, pc=program.symbols["entry"])
    mpu.stPushWord(RETURN_ADDRESS)
    step = mpu.step
    start = time.perf_counter()
    while mpu.pc != 0:
        step()
    return mpu.processorCycles, time.perf_counter() - start


def retro_machine(program, with_device: bool) -> tuple[int, float]:
    machine = Machine()
    machine.load(program)
    if with_device:
        machine.attach(RasterRegister(), DEVICE_START, DEVICE_END)
    start = time.perf_counter()
    result = machine.call("entry")
    return result.cycles, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    rounds = parser.parse_args().rounds
    plain = assemble_text(LOOP.format(outer=OUTER_ROUNDS, device_read=""))
    reading = assemble_text(LOOP.format(outer=OUTER_ROUNDS, device_read="        bit $d012\n"))
    cases = {
        "bare py65, RAM loop": lambda: bare_py65(plain),
        "Machine, plain RAM": lambda: retro_machine(plain, with_device=False),
        "Machine, device mapped, untouched": lambda: retro_machine(plain, with_device=True),
        "bare py65, loop reading $D012 (RAM)": lambda: bare_py65(reading),
        "Machine, loop reading the device": lambda: retro_machine(reading, with_device=True),
    }
    best: dict[str, float] = {name: 0.0 for name in cases}
    cycles: dict[str, int] = {}
    for _ in range(rounds):
        for name, run in cases.items():
            count, seconds = run()
            cycles[name] = count
            best[name] = max(best[name], count / seconds / 1e6)
    assert cycles["bare py65, RAM loop"] == cycles["Machine, plain RAM"] == cycles["Machine, device mapped, untouched"]
    assert cycles["bare py65, loop reading $D012 (RAM)"] == cycles["Machine, loop reading the device"]
    print(f"emulated MHz, best of {rounds} rounds ({cycles['bare py65, RAM loop']:,} and "
          f"{cycles['Machine, loop reading the device']:,} cycles per run)")
    for name, mhz in best.items():
        print(f"  {name:<40} {mhz:6.2f} MHz")
    ram_base = best["bare py65, RAM loop"]
    read_base = best["bare py65, loop reading $D012 (RAM)"]
    print("ratios")
    print(f"  Machine, plain RAM / bare py65                {best['Machine, plain RAM'] / ram_base:5.2f}x")
    untouched = best["Machine, device mapped, untouched"] / ram_base
    print(f"  Machine, device mapped, untouched / bare py65 {untouched:5.2f}x  (goal >= 0.85x: "
          f"{'met' if untouched >= 0.85 else 'NOT met'})")
    print(f"  Machine, reading the device / bare py65 (RAM) {best['Machine, loop reading the device'] / read_base:5.2f}x")


if __name__ == "__main__":
    main()
