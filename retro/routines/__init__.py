"""The 6502 routines: specs (asm/NAME.toml or the user's), their cases, the runner and the references."""
