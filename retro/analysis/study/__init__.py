"""The speed/accuracy study (issue 7): which collision method to use, at what cost, and where it fails.

Layers, bottom up:
- `corpus`: shapes from sprites/ and every relative offset of a pair where their sprite boxes meet,
  with the ground truth (pixel overlap under the VIC-II's opacity rules), all offsets at once.
- `methods`: each method's verdict on every case of a pair (numpy, vectorised over offsets).
- `accuracy`: confusion counts and rates per pair and overall; the counting rules.
- `costs`: 6502 cycles measured in the emulator on the project's routines, bytes of code and tables,
  host microseconds of the Python references.
- `pareto`, `report`, `chart`: the figures (CSV, Markdown, PNG).
- `stability/`: tunnelling, coordinate wrap, arithmetic range, edge conventions, latch pitfalls.
- `advisor`: the cheapest method that meets an accuracy target on a scene's shapes.
"""
