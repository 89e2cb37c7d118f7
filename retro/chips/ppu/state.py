"""`PpuState`: the PPU state one frame of rendering depends on, as plain data.

The scene loader builds it from a TOML file; the bus device builds it from what a 6502 program
wrote to the registers. The hit model (`retro.chips.ppu.hit`) reads nothing else.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from retro.chips.ppu.constants import (
    CHR_SIZE,
    CIRAM_SIZE,
    MIRRORING,
    NAMETABLE_SIZE,
    NTSC,
    OAM_SIZE,
    VideoStandard,
)


@dataclass(frozen=True)
class PpuState:
    ctrl: int = 0                   # $2000 (bits 0-1: base nametable, bit 3/4: pattern tables, bit 5: 8x16)
    mask: int = 0                   # $2001
    scroll_x: int = 0               # the two $2005 writes (coarse and fine together)
    scroll_y: int = 0
    mirroring: str = "horizontal"
    video: VideoStandard = NTSC
    oam: bytes = bytes(OAM_SIZE)
    chr: bytes = bytes(CHR_SIZE)    # pattern tables $0000-$1FFF
    ciram: bytes = bytes(CIRAM_SIZE)  # the console's 2 KiB of nametable RAM
    _arrays: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def chr_array(self) -> np.ndarray:
        return self._cached("chr", self.chr)

    def nametables(self) -> np.ndarray:
        """(4, 1024) uint8: the four logical nametables as the mirroring maps them onto CIRAM."""
        if "nt" not in self._arrays:
            ciram = np.frombuffer(self.ciram, dtype=np.uint8).reshape(-1, NAMETABLE_SIZE)
            self._arrays["nt"] = ciram[list(MIRRORING[self.mirroring])]
        return self._arrays["nt"]

    def _cached(self, key: str, data: bytes) -> np.ndarray:
        if key not in self._arrays:
            self._arrays[key] = np.frombuffer(data, dtype=np.uint8)
        return self._arrays[key]
