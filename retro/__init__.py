"""retro: collision detection on retro hardware (Commodore 64 VIC-II, NES PPU)."""

__version__ = "0.1.0"
