"""The `retro` console command and `python -m retro`: stop signals are handled before anything heavy
is imported, so Ctrl-C at any moment (imports included) gives one line and exit 130, and SIGTERM or
SIGHUP one line and 128 + the signal's number, with no traceback and no temp file left."""

from __future__ import annotations

import os
import sys

from retro import interrupts


def main(argv: list[str] | None = None) -> int:
    interrupts.install()
    try:
        from retro.cli import main as run_command  # numpy, Pillow, ...: a second or so

        code = run_command(argv)
        if code != interrupts.stop_exit_code():  # a stop whose exception Python dropped: still a stop
            interrupts.raise_if_stopping()
    except KeyboardInterrupt as exc:  # before or after the command's own handling (imports, exit)
        print(f"retro: {interrupts.describe(exc)}", file=sys.stderr)
        code = interrupts.exit_code(exc)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, KeyboardInterrupt):
            pass
    if interrupts.stopping():
        # Cleanup has run (temp files, workers, the embedded cluster closed: retro.workers): skip the
        # interpreter's teardown of numpy, matplotlib and Dask, half a second or more of the stop.
        os._exit(code)
    interrupts.exit_now_on_signal()
    return code

