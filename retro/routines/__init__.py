"""The 6502 routines: specs (asm/NAME.toml or the user's), their cases, the runner and the references.

Kept import-light: `retro.tables` imports `retro.routines.screen` for the C64 screen layout.
"""
