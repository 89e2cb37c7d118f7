"""NES machine speed: a cartridge run from reset, frames per second, with the PPU's flag models as they
are and with the sprite overflow model switched off, side by side in one run.

The cartridge is built here (no ROM file needed): it turns rendering on with 9 sprites on a line and
sprite 0 over a solid background, and polls $2002 forever, so every frame has a hit, an overflow and
a vblank flag for the device to catch up with. Prints frames/s of both and their ratio: the cost of
sprite overflow on a frame.

    python benchmarks/nes_frame.py [--frames N]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from retro.analysis.console_run import run_cartridge  # noqa: E402
from retro.chips.cartridge import read_nrom  # noqa: E402
from retro.chips.ines import nrom_image  # noqa: E402
from retro.chips.ppu import device as ppu_device  # noqa: E402

PROGRAM = [
    0xA2, 0x00,              # ldx #0
    0xBD, 0x40, 0xC0,        # copy: lda oam,x
    0x9D, 0x00, 0x02,        #       sta $0200,x
    0xE8, 0xD0, 0xF7,        #       inx / bne copy
    0xA9, 0x20, 0x8D, 0x06, 0x20, 0xA9, 0x00, 0x8D, 0x06, 0x20,   # $2006 = $2000
    0xA9, 0x01, 0xA0, 0x00,  # lda #1 (tile 1), ldy #0
    0x8D, 0x07, 0x20, 0xC8, 0xD0, 0xFA,                          # 256 x sta $2007
    0xA9, 0x02, 0x8D, 0x14, 0x40,                                # OAM DMA from $0200
    0xA9, 0x18, 0x8D, 0x01, 0x20,                                # rendering on
    0x2C, 0x02, 0x20, 0x4C, 0x29, 0xC0,                          # poll: bit $2002 / jmp poll
]


def cartridge():
    prg = bytearray([0xEA] * 0x4000)
    prg[:len(PROGRAM)] = bytes(PROGRAM)
    oam = bytearray([0xF0] * 256)
    for n in range(9):
        oam[4 * n:4 * n + 4] = bytes([40, 1, 0, 8 + 16 * n])
    prg[0x40:0x40 + 256] = oam
    prg[0x3FFC:0x3FFE] = bytes([0x00, 0xC0])
    chr_rom = bytearray(0x2000)
    chr_rom[16:32] = bytes([0xFF] * 16)  # tile 1 solid in table 0
    return read_nrom(nrom_image(bytes(prg), bytes(chr_rom), "horizontal"), "benchmark cartridge")


def frames_per_second(frames: int) -> tuple[float, list]:
    start = time.perf_counter()
    run = run_cartridge(cartridge(), frames=frames)
    return frames / (time.perf_counter() - start), run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=120)
    frames = parser.parse_args().frames
    with_overflow, run = frames_per_second(frames)
    assert run.ppu.hits and run.ppu.overflows, "the benchmark frame must hit and overflow"
    original = ppu_device.PpuDevice._next_overflow
    ppu_device.PpuDevice._next_overflow = lambda self: None
    try:
        without, _ = frames_per_second(frames)
    finally:
        ppu_device.PpuDevice._next_overflow = original
    print(f"{frames} frames: {with_overflow:.1f} frames/s with sprite overflow, {without:.1f} without; "
          f"ratio {with_overflow / without:.3f}")


if __name__ == "__main__":
    main()
