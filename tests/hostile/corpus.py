"""A generated corpus of hostile inputs: every value of every key of real input files (scenes,
routine specs, method files) and every option of every command replaced, one at a time, by values
that have broken tools before (huge and long numbers, wrong types, deep nesting, odd strings, paths
to directories and devices). `cases()` yields them; tests/hostile/test_corpus.py runs them.

Run `python tests/hostile/corpus.py` to print the corpus size per command.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from retro.fileio import toml_text, toml_value

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

# TOML values (as TOML text) that must never give more than one line and exit 2
HOSTILE_TOML = [
    "-1", "0", "65536", "4294967296", "9" * 5000, "-" + "9" * 40, "1.5", "nan", "inf", "true", '""',
    '"$"', '"$ZZZZ"', '"0x"', '"%2"', '"' + "A" * 10_000 + '"', '"\\u0000"', '"../../../../etc/passwd"',
    '"/dev/zero"', '"/"', "[]", "[1, 2, 3]", "[[]]", "{}", '{ a = 1 }', "[" * 200 + "]" * 200,
    "1979-05-27", '"\U0001F600"',
]
# command-line option values
HOSTILE_ARGS = ["-1", "0", "99999999999999999999", "9" * 5000, "1.5", "", "abc", "$", "0x", "%", "/dev/zero", "/",
                "nan", "--", "\U0001F600"]


@dataclass(frozen=True)
class Case:
    name: str
    files: dict  # file name -> text, written into a fresh folder
    argv: tuple  # "{dir}" is replaced by that folder
    # what an error must name: the file and key of a TOML value, or the option (its value for a file name)
    names: tuple = ()
    refused: bool = False  # exit 2 is the only right answer (an empty file name is no file name)


def _paths(doc, prefix=()) -> Iterator[tuple]:
    """Every key path of a TOML document (tables and arrays of tables walked into)."""
    if isinstance(doc, dict):
        for key, value in doc.items():
            yield prefix + (key,)
            yield from _paths(value, prefix + (key,))
    elif isinstance(doc, list):
        for i, value in enumerate(doc):
            if isinstance(value, dict):
                yield from _paths(value, prefix + (i,))


def _replace(doc, path: tuple, marker: str):
    """A deep copy of doc with the value at path replaced by a marker string."""
    if not path:
        return marker
    head, rest = path[0], path[1:]
    if isinstance(doc, dict):
        return {k: (_replace(v, rest, marker) if k == head else v) for k, v in doc.items()}
    return [(_replace(v, rest, marker) if i == head else v) for i, v in enumerate(doc)]


MARKER = "@@HOSTILE@@"


def _mutations(text: str) -> Iterator[tuple[str, str, str]]:
    """(description, TOML text, the key) for every key path of a document and every hostile value."""
    doc = tomllib.loads(text)
    for path in _paths(doc):
        template = toml_text(_replace(doc, path, MARKER))
        key = next(str(step) for step in reversed(path) if not isinstance(step, int))
        for value in HOSTILE_TOML:
            yield ".".join(map(str, path)) + " = " + value[:20], template.replace(toml_value(MARKER), value), key


def _files_of(folder: Path, names: list[str]) -> dict:
    return {name: (folder / name).read_bytes() for name in names}


def cases() -> Iterator[Case]:
    # scenes: every key of the examples' VIC-II and NES scenes
    for scene, command in (("vic_two_balls.toml", "vic"), ("vic_text_collision.toml", "vic"),
                           ("nes_sprite0.toml", "nes")):
        sprites = {p.name: p.read_bytes() for p in (ROOT / "sprites").glob("*.spr")}
        for what, text, key in _mutations((EXAMPLES / scene).read_text()):
            yield Case(f"{command} {scene}: {what}", {"examples/scene.toml": text,
                                                      **{f"sprites/{k}": v for k, v in sprites.items()}},
                       (command, "{dir}/examples/scene.toml", "--json"), ("scene.toml", key))
    # routine specs: every key of the example spec
    boxhit = EXAMPLES / "boxhit"
    extra = _files_of(boxhit, ["boxhit.asm", "boxhit.prg", "boxhit.sym", "boxhit_ref.py"])
    for what, text, key in _mutations((boxhit / "boxhit.toml").read_text()):
        yield Case(f"check boxhit.toml: {what}", {"boxhit.toml": text, **extra},
                   ("check", "{dir}/boxhit.toml", "--random", "20", "--jobs", "1", "--json"), ("boxhit.toml", key))
    # method files: every key of the example methods
    for method in ("shrunk_box.toml", "cross.toml"):
        extra = _files_of(EXAMPLES / "methods", ["cross.py"])
        for what, text, key in _mutations((EXAMPLES / "methods" / method).read_text()):
            yield Case(f"advise --method {method}: {what}", {"m.toml": text, **extra},
                       ("advise", str(EXAMPLES / "vic_two_balls.toml"), "--method", "{dir}/m.toml", "--jobs", "1",
                        "--quiet"), ("m.toml", key))
    # command-line options: every option value of the commands
    scene = str(EXAMPLES / "vic_two_balls.toml")
    nes = str(EXAMPLES / "nes_sprite0.toml")
    commands = {
        "run": (["run", "{dir}/ok.s", "--entry", "entry"],
                ["--entry", "--a", "--x", "--y", "--c", "--load", "--budget", "--set", "--peek", "--labels"]),
        "asm": (["asm", "{dir}/ok.s"], ["-o", "--labels", "--list"]),
        "vic": (["vic", scene], ["--frames", "--scale", "--palette", "--png"]),
        "nes": (["nes", nes], ["--scale", "--png"]),
        "check": (["check", "mul8", "--jobs", "1"], ["--random", "--seed", "--jobs", "--engine", "--at-line"]),
        "cycles": (["cycles", "mul8", "--jobs", "1"], ["--random", "--seed", "--scene"]),
        "advise": (["advise", scene, "--quiet"], ["--accuracy", "--jobs", "--method"]),
        "parry": (["parry", "--out", "{dir}/out"], ["--frames", "--script"]),
    }
    source = {"ok.s": "        .org $c000\nentry:  lda #1\n        rts\n"}
    for command, (base, options) in commands.items():
        for option in options:
            for value in HOSTILE_ARGS:
                names_a_file = option in FILE_OPTIONS
                yield Case(f"{command} {option} {value[:20]!r}", source, tuple(base) + (option, value),
                           names=(value[:20],) if names_a_file and value and value != "--" else (option,),
                           refused=names_a_file and not value)


# options whose value is a file name (read or written): an error names the file, an empty name is refused
FILE_OPTIONS = {"-o", "--labels", "--list", "--png", "--script", "--scene", "--method"}


if __name__ == "__main__":
    counts: dict[str, int] = {}
    for case in cases():
        key = case.argv[0]
        counts[key] = counts.get(key, 0) + 1
    print(counts, sum(counts.values()))
