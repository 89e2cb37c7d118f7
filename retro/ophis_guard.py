"""Ophis with bounds: what retro.assembler runs in the assembler's own process (retro never imports it).

    python -c RUNNER ophis_guard.py SOURCE_LIMIT BINARY_LIMIT OPHIS-ARGUMENTS...

Ophis reads the files a source names itself (`.include`, `.require`, `.incbin`, `.charmapbin`), so
the bounds retro puts on every file it reads are put here, around Ophis's file reads:
- a file that is not a regular file (a device such as /dev/zero, a FIFO, a folder) is refused by its
  kind before it is opened;
- the sources read in one run (the top file and everything it includes) total at most SOURCE_LIMIT
  bytes, checked from their sizes before they are read (Ophis holds about 100 bytes per source byte);
- one `.incbin` brings in at most BINARY_LIMIT bytes (the 6502 sees 64 KiB; a larger file can still
  be cut with the directive's offset and length);
- no byte is emitted past $FFFF: code or data that an `.org` puts beyond the address space.
Every file Ophis reads is also named in the file RETRO_OPENED gives, for retro to record as an
input of the command (one no output may replace).
Each refusal is an Ophis error at the line that caused it (`file:line: message`), so retro reports
it like any other assembly error. It runs as a file in the assembler's own interpreter, which
imports of retro only the file checks it shares with retro.fileio.
"""

from __future__ import annotations

import builtins
import os
import sys

from retro.fileio import file_kind

ADDRESS_LIMIT = 0xFFFF
_real_open = builtins.open


class Refused(OSError):
    """A read refused here; Ophis catches OSError and adds its own 'Could not read' after ours."""


class _Guard:
    def __init__(self, source_limit: int, binary_limit: int, listing=None) -> None:
        self.source_limit = source_limit
        self.binary_limit = binary_limit
        self.source_bytes = 0
        self.past_end_reported = False
        self.listing = listing  # where every file Ophis reads is named (NUL-separated), or None

    def refuse(self, message: str) -> Refused:
        from Ophis import Errors

        Errors.log(message)
        return Refused(message)

    def open(self, file, mode="r", *args, **kwargs):
        if isinstance(file, int) or any(flag in mode for flag in "wax+"):
            return _real_open(file, mode, *args, **kwargs)
        name = os.fsdecode(file)
        try:
            info = os.stat(file)
        except OSError:
            return _real_open(file, mode, *args, **kwargs)  # Ophis's own "Could not read" follows
        if self.listing is not None:  # retro records it as an input of the command, which no output may replace
            self.listing.write(os.path.abspath(name) + chr(0))
            self.listing.flush()
        kind = file_kind(info.st_mode)
        if kind:
            raise self.refuse(f"{name}: is {kind}, not a regular file")
        if "b" in mode:
            return _Bounded(_real_open(file, mode, *args, **kwargs), name, self)
        self.source_bytes += info.st_size
        if self.source_bytes > self.source_limit:
            raise self.refuse(f"{name}: the sources of this program total more than {self.source_limit >> 20} MiB")
        return _real_open(file, mode, *args, **kwargs)


class _Bounded:
    """A binary file whose reads bring in at most the guard's binary limit."""

    def __init__(self, stream, name: str, guard: _Guard) -> None:
        self.stream, self.name, self.guard = stream, name, guard

    def read(self, size: int = -1) -> bytes:
        left = os.fstat(self.stream.fileno()).st_size - self.stream.tell()
        wanted = left if size is None or size < 0 else min(size, left)
        if wanted > self.guard.binary_limit:
            raise self.guard.refuse(f"{self.name}: {wanted} bytes to include, more than the "
                                    f"{self.guard.binary_limit} the 6502 can address (give an offset and a length)")
        return self.stream.read(size)

    def seek(self, *args):
        return self.stream.seek(*args)

    def tell(self):
        return self.stream.tell()

    def close(self):
        return self.stream.close()


def _stop_past_address_space(guard: _Guard) -> None:
    """Every way the assembler pass emits bytes, checked after it has emitted them (`tee` holds the
    bytes of the current line so far, which start at the line's program counter)."""
    from Ophis import Errors, Passes

    def checked(emit):
        def emit_checked(self, expr, env, tee=None):
            emit(self, expr, env, tee)
            if self.writeOK and tee is not None and not guard.past_end_reported:
                last = env.getPC() + len(tee) - 1
                if last > ADDRESS_LIMIT:
                    guard.past_end_reported = True
                    Errors.log(f"code or data at ${last:X}, past ${ADDRESS_LIMIT:04X}, the end of the 6502's address space")
        return emit_checked

    for name in ("outputbyte", "outputword", "outputdword", "outputword_be", "outputdword_be"):
        if hasattr(Passes.Assembler, name):
            setattr(Passes.Assembler, name, checked(getattr(Passes.Assembler, name)))


def main(argv: list[str]) -> int:
    source_limit, binary_limit, *ophis_args = argv
    listed = os.environ.get("RETRO_OPENED")
    listing = _real_open(listed, "w", encoding="utf-8", errors="surrogateescape") if listed else None
    guard = _Guard(int(source_limit), int(binary_limit), listing)
    builtins.open = guard.open
    _stop_past_address_space(guard)
    from Ophis.Main import run_ophis

    return run_ophis(ophis_args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
