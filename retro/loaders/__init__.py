"""Programs and symbol files as other tools write them: PRG, raw binaries, iNES images, Ophis
source, and the symbol files of the common 6502 assemblers (docs/symbols.md)."""

from retro.loaders.binaries import load_program, refuse_foreign_source
from retro.loaders.symbols import (
    Symbol,
    detect_format,
    load_symbol_tables,
    parse_symbols,
    read_symbols,
    symbol_tables,
)

__all__ = ["Symbol", "detect_format", "load_program", "load_symbol_tables", "parse_symbols", "read_symbols",
           "refuse_foreign_source", "symbol_tables"]
