"""Rendering: palettes, images of scenes and overlaps, charts. Pillow and matplotlib live here only."""
