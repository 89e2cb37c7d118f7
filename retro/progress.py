"""Progress reports of long commands: one callable type, one printer (stderr), one silence."""

from __future__ import annotations

import sys
from collections.abc import Callable

Progress = Callable[[str], None]


def stderr_progress(message: str) -> None:
    """Progress goes to stderr so that stdout stays the command's answer (a table, JSON)."""
    print(message, file=sys.stderr, flush=True)


def quiet(message: str) -> None:
    pass


def progress_printer(quiet_flag: bool) -> Progress:
    return quiet if quiet_flag else stderr_progress
