"""The error types the CLI turns into one line and an exit code.

InputError: the user gave something we cannot use (bad file, bad value, bad scene): exit 2.
RunError: the input was fine but the 6502 routine failed (budget, BRK, JAM, unstable opcode): exit 1.
"""

from __future__ import annotations


class RetroError(Exception):
    """Base class: the message is one line, ready to print."""

    exit_code = 2


class InputError(RetroError, ValueError):
    """Bad input: names the file, line or field at fault."""

    exit_code = 2


class RunError(RetroError, RuntimeError):
    """A 6502 run that stopped abnormally; says where it was."""

    exit_code = 1


def where(source: str | None, field: str | None = None, line: int | None = None) -> str:
    """Format the location prefix of an error message: 'FILE:LINE: field: '."""
    parts = []
    if source:
        parts.append(str(source) + (f":{line}" if line is not None else ""))
    if field:
        parts.append(field)
    return ": ".join(parts) + (": " if parts else "")
