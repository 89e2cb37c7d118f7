"""The `retro` console command and `python -m retro`: stop signals are handled before anything heavy
is imported, so Ctrl-C at any moment (imports included) gives one line and exit 130, and SIGTERM or
SIGHUP one line and 128 + the signal's number, with no traceback and no temp file left."""

from __future__ import annotations

import sys

from retro import interrupts


def main(argv: list[str] | None = None) -> int:
    interrupts.install()
    try:
        from retro.cli import main as run_command  # numpy, Pillow, ...: a second or so

        code = run_command(argv)
    except KeyboardInterrupt as exc:  # before or after the command's own handling (imports, exit)
        print(f"retro: {interrupts.describe(exc)}", file=sys.stderr)
        code = interrupts.exit_code(exc)
    try:
        sys.stdout.flush()
    except (BrokenPipeError, KeyboardInterrupt):
        pass
    interrupts.exit_now_on_signal()
    return code
