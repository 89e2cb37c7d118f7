"""The collision routines in asm/: their registry (entry <-> reference <-> inputs), harness and layout.

Kept import-light: `retro.tables` imports `retro.routines.screen` for the C64 screen layout.
"""
