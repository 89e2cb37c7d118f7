"""`retro stability`: where collision methods break (tunnelling, wrap, ranges, edges, latch pitfalls)."""
