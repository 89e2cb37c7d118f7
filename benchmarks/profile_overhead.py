"""What `retro profile` costs: the same program run plain and profiled, side by side in one run.

Two runs, each ROUNDS times interleaved (the best round counts, the least disturbed by other
processes on the machine):
  1. a C64 program from its SYS line, a raster interrupt every frame whose handler calls a
     subroutine, the main loop calling two nested subroutines forever, for FRAMES frames;
  2. the same program's main loop on a NES cartridge (from reset) for FRAMES frames.
Goal (issue 25): profiled <= 2x plain.

    python benchmarks/profile_overhead.py [--rounds N] [--frames N]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from retro.chips.ines import nrom_image
from retro.commands import profile as profile_command
from retro.commands import run as run_command

BASIC_STUB = bytes([0x0B, 0x08, 0x0A, 0x00, 0x9E]) + b"2061" + bytes([0, 0, 0])  # 10 SYS 2061
CODE = 0x080D


def c64_program() -> bytes:
    """SEI; $0314 = irq; $D011 = $1B; $D012 = 100; $D01A = 1; ack; CLI; loop: JSR a; JMP loop;
    a: JSR b; INC $C000; RTS; b: NOP; RTS; irq: JSR b; LSR $D019; JMP $EA81."""
    main = [0x78, 0xA9, 0, 0x8D, 0x14, 0x03, 0xA9, 0, 0x8D, 0x15, 0x03, 0xA9, 0x1B, 0x8D, 0x11, 0xD0,
            0xA9, 100, 0x8D, 0x12, 0xD0, 0xA9, 0x01, 0x8D, 0x1A, 0xD0, 0x8D, 0x19, 0xD0, 0x58]
    loop = CODE + len(main)
    a = loop + 6
    b = a + 7
    irq = b + 2
    main += [0x20, a & 0xFF, a >> 8, 0x4C, loop & 0xFF, loop >> 8,          # loop: JSR a / JMP loop
             0x20, b & 0xFF, b >> 8, 0xEE, 0x00, 0xC0, 0x60,                 # a: JSR b / INC $C000 / RTS
             0xEA, 0x60,                                                     # b: NOP / RTS
             0x20, b & 0xFF, b >> 8, 0x4E, 0x19, 0xD0, 0x4C, 0x81, 0xEA]     # irq: JSR b / LSR $D019 / JMP $EA81
    main[2], main[7] = irq & 0xFF, irq >> 8
    return (0x0801).to_bytes(2, "little") + BASIC_STUB + bytes(main)


def nes_cartridge() -> bytes:
    """At $C000: loop: JSR a / JMP loop; a: JSR b / INC $0300 / RTS; b: NOP / RTS."""
    code = [0x20, 0x06, 0xC0, 0x4C, 0x00, 0xC0, 0x20, 0x0D, 0xC0, 0xEE, 0x00, 0x03, 0x60, 0xEA, 0x60]
    prg = bytearray([0xEA] * 0x4000)
    prg[:len(code)] = bytes(code)
    prg[-4:-2] = (0xC000).to_bytes(2, "little")
    return nrom_image(bytes(prg), bytes(0x2000), "vertical")


def best(function, rounds: int) -> float:
    times = []
    for _ in range(rounds):
        began = time.perf_counter()
        function()
        times.append(time.perf_counter() - began)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--frames", type=int, default=20)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        prg = Path(folder) / "irq.prg"
        prg.write_bytes(c64_program())
        nes = Path(folder) / "loop.nes"
        nes.write_bytes(nes_cartridge())
        for name, path, plain in (
                ("C64 .prg, raster IRQ", prg, lambda p: run_command.run_c64_program(p, frames=args.frames)),
                ("NES cartridge", nes, lambda p: run_command.run_console(p, frames=args.frames))):
            plain_time = best(lambda: plain(path), args.rounds)
            profiled_time = best(lambda: profile_command.profile(path, frames=args.frames), args.rounds)
            print(f"{name:<22} {args.frames} frames: plain {plain_time:.3f} s, profiled {profiled_time:.3f} s, "
                  f"ratio {profiled_time / plain_time:.2f}x (goal <= 2x)")


if __name__ == "__main__":
    main()
