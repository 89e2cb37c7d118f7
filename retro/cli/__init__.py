"""The `retro` command line: parse, call one function, print.

Each subcommand lives in its own module in this package (listed in `_command_modules`) and exposes
`register(subparsers)`, which adds its parser and sets `func(args) -> int`.
Every RetroError becomes one line on stderr and its exit code; argparse usage errors exit 2.
"""

from __future__ import annotations

import argparse
import sys

from retro import __version__
from retro.errors import RetroError


def one_line(text: str) -> str:
    """User text (file names, TOML keys) echoed in a message can hold newlines or terminal escapes:
    show every control character as a Python escape so the error stays one plain line."""
    return "".join(repr(c)[1:-1] if ord(c) < 0x20 or ord(c) == 0x7F else c for c in text)


def _command_modules() -> list:
    """The subcommands' modules, in the order `retro --help` lists them (plain imports: grep and
    "find usages" follow them)."""
    from retro.cli import advise, asm, chart, check, cycles, demo, nes, parry, run, stability, vic

    return [demo, asm, run, vic, nes, check, cycles, chart, stability, advise, parry]


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("allow_abbrev", False)  # `--exhaustiv` must not pass for `--exhaustive`
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # one line, exit 2, no usage dump
        print(one_line(f"{self.prog}: {message}"), file=sys.stderr)
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="retro", description="Collision detection on retro hardware (C64, NES).")
    parser.add_argument("--version", action="version", version=f"retro {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for module in _command_modules():
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except RetroError as exc:
        print(one_line(f"retro {args.command}: {exc}"), file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print(f"retro {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 1
