"""The VIC-II (6569 PAL, 6567R8 NTSC) collision model: constants, graphics decode, frame model, bus device."""
