"""The VIC-II (6569 PAL, 6567R8 NTSC, 6567R56A old NTSC) collision model: constants, graphics decode,
frame model, bus device."""
