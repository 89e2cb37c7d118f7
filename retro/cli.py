"""The `retro` command line: one subcommand per module of retro.commands, each module holding its
command whole (the function, its options beside it in `add_options`, and `main`, which calls the
function and prints). A command's run imports its own module only (`retro check` need not load what
`retro advise` or `retro optimize` use: about 0.2 CPU-s a process); `retro --help`, a usage error before
the command and an unknown command build the whole parser. Options several commands share are defined
once (retro.commands.options). The
command functions check their own arguments (numbers arrive as the text typed), so nothing is validated
twice. Every RetroError becomes one line on stderr and its exit code (2 for bad input, 1 for a routine
or check that fails); argparse usage errors exit 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from types import ModuleType

from retro import __version__, interrupts
from retro.errors import RetroError

# The commands, each a module of retro.commands by the same name, in the order `retro --help` lists them.
COMMANDS = ("demo", "asm", "run", "vic", "nes", "check", "cycles", "chart", "stability", "advise", "parry", "profile",
            "optimize")


def command_module(name: str) -> ModuleType:
    """The module that holds command `name` whole (imported on first use)."""
    return importlib.import_module(f"retro.commands.{name}")


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
    """The command line's parser: every command's, or only command `only`'s (what a run of that command
    needs: its arguments parse the same either way)."""
    parser = _Parser(prog="retro", description="Collision detection on retro hardware (C64, NES).")
    parser.add_argument("--version", action="version", version=f"retro {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS if only is None else (only,):
        command = command_module(name)
        p = sub.add_parser(name, help=command.HELP, **getattr(command, "PARSER", {}))
        command.add_options(p)
        p.set_defaults(func=command.main)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(argv[0] if argv and argv[0] in COMMANDS else None)
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
