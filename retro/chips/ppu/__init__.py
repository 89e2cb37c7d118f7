"""The NES PPU (2C02 NTSC, 2C07 PAL) as far as collision goes: the sprite-zero hit.

- `constants`: every hardware number, named once.
- `state.PpuState`: the state one frame depends on (registers, OAM, CHR, nametable RAM).
- `pixels`: background and sprite-0 pattern values at screen pixels (scrolling, flips, 8x16).
- `hit.sprite_zero_hit(state)`: the model: hit or not, pixel, line, dot, dots after vblank.
- `clock`: CPU cycle clock -> PPU dots and frames.
- `device.PpuDevice`: the registers on the 2A03 machine's bus, $2002 timed by the CPU clock.
"""

from retro.chips.ppu.hit import SpriteZeroHit, sprite_zero_hit
from retro.chips.ppu.state import PpuState

__all__ = ["PpuState", "SpriteZeroHit", "sprite_zero_hit"]
