"""The `retro` command line: one subcommand per module of retro.commands, each module holding its
command whole (the function, its options beside it in `add_options`, and `main`, which calls the
function and prints). Options several commands share are defined once (retro.commands.options). The
command functions check their own arguments (numbers arrive as the text typed), so nothing is validated
twice. Every RetroError becomes one line on stderr and its exit code (2 for bad input, 1 for a routine
or check that fails); argparse usage errors exit 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Iterator, Mapping

from retro import __version__, interrupts
from retro.errors import RetroError


class _Commands(Mapping):
    """Command name -> its module in retro.commands, imported when first asked for: `retro check` loads
    check's module and what it needs, not every command's (about 0.08 s of each run's start)."""

    NAMES = ("demo", "asm", "run", "vic", "nes", "check", "cycles", "chart", "stability", "advise", "parry",
             "profile", "optimize")  # in the order `retro --help` lists them

    def __getitem__(self, name: str):
        if name not in self.NAMES:
            raise KeyError(name)
        return importlib.import_module(f"retro.commands.{name}")

    def __contains__(self, name: object) -> bool:
        return name in self.NAMES

    def __iter__(self) -> Iterator[str]:
        return iter(self.NAMES)

    def __len__(self) -> int:
        return len(self.NAMES)


COMMANDS = _Commands()


def one_line(text: str) -> str:
    """User text (file names, TOML keys) echoed in a message can hold newlines or terminal escapes:
    show every control character as a Python escape so the error stays one plain line."""
    return "".join(repr(c)[1:-1] if ord(c) < 0x20 or ord(c) == 0x7F else c for c in text)


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("allow_abbrev", False)  # `--exhaustiv` must not pass for `--exhaustive`
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # one line, exit 2, no usage dump
        print(one_line(f"{self.prog}: {message}"), file=sys.stderr)
        raise SystemExit(2)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The parser of every command, or with `only`, of that command whole and the others' names (what
    parsing a line that starts with `only` needs: no other command's module is imported)."""
    parser = _Parser(prog="retro", description="Collision detection on retro hardware (C64, NES).")
    parser.add_argument("--version", action="version", version=f"retro {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        if only is not None and name != only:
            sub.add_parser(name)
            continue
        command = COMMANDS[name]
        p = sub.add_parser(name, help=command.HELP, **getattr(command, "PARSER", {}))
        command.add_options(p)
        p.set_defaults(func=command.main)
    return parser


def main(argv: list[str] | None = None) -> int:
    line = sys.argv[1:] if argv is None else argv
    parser = build_parser(line[0] if line and line[0] in COMMANDS else None)
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except RetroError as exc:
        print(one_line(f"retro {args.command}: {exc}"), file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM/SIGHUP once retro.entry installed its handlers
        print(f"retro {args.command}: {interrupts.describe(exc)}", file=sys.stderr)
        return interrupts.exit_code(exc)
    except BrokenPipeError:
        return 1
