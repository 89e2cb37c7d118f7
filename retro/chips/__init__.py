"""Chip models (VIC-II, NES PPU): pure models of what the hardware reports, and bus devices."""
