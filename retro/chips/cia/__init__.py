"""The 6526 CIA as far as a C64 program run needs it (retro.chips.cia.timers: CIA 1's interval timers)."""
