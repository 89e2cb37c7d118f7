"""A mutational fuzzer over every file format retro reads, seeded from the project's own fixtures.

Each seed is a valid file of one format, with what the mutations need to know about it (its header
bytes, its 16-bit size and count fields, whether it is text, TOML or JSON) and the way a user's
command reads it (`Target`: a command function called in-process, and the same command line for
the subprocess sample). The mutations, drawn deterministically from a seed number:
- truncations (empty, 1 and 2 bytes, at and around the header's end, half, all but one byte);
- bit flips and bytes set to $00/$FF at random places;
- each header byte at 0, $FF (the maximum) and $80 / $7F (negative and largest positive as signed);
- each 16-bit size or count field at 0, $FFFF and $8000 (huge declared sizes);
- growth: 64 KiB appended, the file twice over;
- text: UTF-16 with a byte order mark, a Latin-1 byte, a NUL, a UTF-8 byte order mark, CR LF lines,
  a 10,000-digit number;
- TOML and JSON: every key's value replaced by each other type (integer, float, boolean, string,
  array, table, date, a 5,000-digit integer).
`cases(seed_numbers)` yields them; tests/hostile/test_fuzz.py runs them and says what clean means.

Run `python tests/hostile/fuzz.py` to print the number of cases per format.
"""

from __future__ import annotations

import json
import random
import struct
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "formats"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from corpus import _paths, _replace  # noqa: E402

from retro.fileio import toml_text, toml_value  # noqa: E402

SEEDS = (0x6502, 0x2A03)  # the fuzzer's seed numbers: each gives its own random places
FLIPS_PER_SEED = 6
WRONG_TYPES = {  # TOML text of a value of each type
    "integer": "7", "float": "1.5", "boolean": "true", "string": '"x"', "array": "[1, 2]", "table": "{ a = 1 }",
    "date": "1979-05-27", "huge integer": "9" * 5000,
}
JSON_WRONG_TYPES = {"integer": 7, "float": 1.5, "boolean": True, "string": "x", "array": [1, 2], "object": {"a": 1},
                    "null": None, "huge integer": "HUGE"}
HUGE_JSON_NUMBER = "9" * 5000


@dataclass(frozen=True)
class Target:
    """How a command reads a file: `files` are written beside it (a scene naming it, a program's
    companions), `call(folder)` runs the command function in-process, `argv` is the command line."""

    command: str
    files: dict = field(default_factory=dict)
    argv: tuple = ()
    exit_1_allowed: bool = False  # a program's routine may fail (RunError): exit 1 is a clean outcome


@dataclass(frozen=True)
class Seed:
    format: str
    name: str  # the file's name in the case folder
    data: bytes
    target: Target
    header: tuple = ()  # offsets of header bytes
    words: tuple = ()  # offsets of 16-bit little-endian size or count fields
    kind: str = "binary"  # "binary", "text", "toml" or "json"


@dataclass(frozen=True)
class Case:
    seed: Seed
    mutation: str
    data: bytes
    field: str | None = None  # the key whose value was replaced: the error must name it

    @property
    def name(self) -> str:
        return f"{self.seed.format} {self.seed.name}: {self.mutation}"


# ---- seeds -------------------------------------------------------------------------------------

def _vic_scene(memory: str = "", sprite: str = "") -> str:
    return ('chip = "vic-ii"\nvideo = "pal"\n[registers]\n"$d011" = 0x1b\n"$d016" = 0xc8\n'
            + (f'[[sprite]]\nindex = 0\nx = 100\ny = 100\ncolor = 1\nfile = "{sprite}"\n' if sprite else
               '[[sprite]]\nindex = 0\nx = 100\ny = 100\ncolor = 1\nfile = "ball.spr"\n')
            + (f"[memory]\n{memory}\n" if memory else ""))


def _nes_scene(chr_file: str = "", nametable: str = "") -> str:
    text = ('chip = "nes"\nvideo = "ntsc"\n[ppu]\nctrl = 0\nmask = 0x1e\n'
            '[[oam]]\ny = 25\ntile = 1\nx = 88\n')
    text += f'[chr]\nfile = "{chr_file}"\n' if chr_file else '[chr]\ntiles = { "0:1" = ' + str(["11111111"] * 8) + " }\n"
    if nametable:
        text += f'[[nametable]]\nindex = 0\nfile = "{nametable}"\n'
    return text


def _vic(name: str, **scene) -> Target:
    return Target("vic", {"scene.toml": _vic_scene(**scene), "ball.spr": (ROOT / "sprites" / "ball.spr").read_bytes()},
                  ("vic", "{dir}/scene.toml", "--json"))


def _nes(**scene) -> Target:
    return Target("nes", {"scene.toml": _nes_scene(**scene)}, ("nes", "{dir}/scene.toml", "--json"))


def _koala() -> bytes:
    # load address $6000, 8000 bitmap bytes, 1000 screen, 1000 colour, the background (Koala layout)
    return struct.pack("<H", 0x6000) + bytes(i * 7 & 0xFF for i in range(8000)) + bytes([0x12] * 1000) \
        + bytes([0x03] * 1000) + bytes([0])


def _spritepad_v1() -> bytes:
    # SpritePad 2.0 beta: "SPD", version 1, count - 1, animations - 1, background, multicolours
    block = (ROOT / "sprites" / "ball.spr").read_bytes()[:64].ljust(64, b"\0")
    return b"SPD" + bytes([1, 1, 0, 6, 2, 7]) + block * 2


def _spritepad_pro() -> bytes:
    block = (ROOT / "sprites" / "ship.spr").read_bytes()[:64].ljust(64, b"\0")
    header = b"SPD" + bytes([5, 0]) + struct.pack("<HH", 2, 0) + bytes([0, 0, 0, 0]) + bytes([6, 2, 7]) \
        + struct.pack("<hh", 1, 1)
    return header + block * 2


def _spritemate() -> bytes:
    pixels = [[(x + y) % 4 for x in range(24)] for y in range(21)]
    doc = {"version": 1.3, "colors": {"0": 11, "2": 7, "3": 10}, "sprites": [
        {"name": "a", "color": 1, "multicolor": False, "double_x": False, "double_y": False, "overlay": False,
         "pixels": pixels},
        {"name": "b", "color": 2, "multicolor": True, "double_x": True, "double_y": False, "overlay": False,
         "pixels": pixels}]}
    return json.dumps(doc).encode()


def _png_sheet() -> bytes:
    import io

    from PIL import Image

    image = Image.new("RGBA", (48, 21), (0, 0, 0, 0))
    for x in range(0, 48, 3):
        for y in range(0, 21, 2):
            image.putpixel((x, y), (255, 255, 255, 255))
    out = io.BytesIO()
    image.save(out, format="PNG")
    return out.getvalue()


def _ines() -> bytes:
    return (ROOT / "tests" / "data" / "foreign" / "nes_boxhit.nes").read_bytes()


def _charpad(version: int) -> bytes:
    import ctm_samples

    return ctm_samples.WRITERS[version](ctm_samples.level_for(version), "per-tile")


def seeds() -> list[Seed]:
    foreign = ROOT / "tests" / "data" / "foreign"
    boxhit = ROOT / "examples" / "boxhit"
    run_prg = Target("run", {}, ("run", "{dir}/{file}", "--entry", "$c000", "--budget", "20000"), exit_1_allowed=True)
    found = [
        # programs
        Seed("prg", "p.prg", (foreign / "acme_boxhit.prg").read_bytes(), run_prg, header=(0, 1), words=(0,)),
        Seed("raw binary", "p.bin", (foreign / "xa_boxhit.bin").read_bytes(),
             Target("run", {}, ("run", "{dir}/{file}", "--load", "$c000", "--entry", "$c000", "--budget", "20000"),
                    exit_1_allowed=True), header=(0, 1)),
        Seed("iNES", "p.nes", _ines(),
             Target("run", {}, ("run", "{dir}/{file}", "--entry", "$8000", "--budget", "20000"), exit_1_allowed=True),
             header=tuple(range(4, 16)), words=(4, 8)),
        Seed("NES 2.0", "p.nes", _ines()[:7] + bytes([_ines()[7] & 0xF3 | 0x08]) + _ines()[8:],
             Target("run", {}, ("run", "{dir}/{file}", "--entry", "$8000", "--budget", "20000"), exit_1_allowed=True),
             header=tuple(range(4, 16)), words=(4, 8, 10, 12, 14)),
        Seed("Ophis source", "p.s", (ROOT / "asm" / "mul8.s").read_bytes(),
             Target("asm", {}, ("asm", "{dir}/{file}", "-o", "{dir}/out.prg")), kind="text"),
        # scenes
        Seed("VIC-II scene", "examples/scene.toml", (ROOT / "examples" / "vic_text_collision.toml").read_bytes(),
             Target("vic", {f"sprites/{p.name}": p.read_bytes() for p in (ROOT / "sprites").glob("*.spr")},
                    ("vic", "{dir}/{file}", "--json")), kind="toml"),
        Seed("NES scene", "scene.toml", (ROOT / "examples" / "nes_8x16_left_clip.toml").read_bytes(),
             Target("nes", {}, ("nes", "{dir}/{file}", "--json")), kind="toml"),
        # routine specs and method files
        Seed("routine spec", "boxhit.toml", (boxhit / "boxhit.toml").read_bytes(),
             Target("spec", {n: (boxhit / n).read_bytes() for n in ("boxhit.prg", "boxhit.sym", "boxhit_ref.py")},
                    ("check", "{dir}/{file}", "--random", "5", "--jobs", "1", "--quiet"), exit_1_allowed=True), kind="toml"),
        Seed("method file", "m.toml", (ROOT / "examples" / "methods" / "cross.toml").read_bytes(),
             Target("method", {"cross.py": (ROOT / "examples" / "methods" / "cross.py").read_bytes()}, ()),
             kind="toml"),
        # sprites
        Seed("raw sprite", "s.spr", (ROOT / "sprites" / "ship.spr").read_bytes(), _vic("s.spr", sprite="s.spr")),
        Seed("SpritePad 2.0 beta", "s.spd", _spritepad_v1(), _vic("s.spd", sprite="s.spd"), header=tuple(range(3, 9))),
        Seed("SpritePad Pro", "s.spd", _spritepad_pro(), _vic("s.spd", sprite="s.spd"), header=tuple(range(3, 20)),
             words=(5, 7, 16, 18)),
        Seed("Spritemate", "s.spm", _spritemate(), _vic("s.spm", sprite="s.spm"), kind="json"),
        Seed("PNG sprite sheet", "s.png", _png_sheet(), _vic("s.png", sprite="s.png"), header=tuple(range(8, 33)),
             words=(16, 18, 20, 22)),
        # C64 screens
        Seed("charset", "c.64c", b"\x00\x30" + bytes(i * 13 & 0xFF for i in range(2048)),
             _vic("c.64c", memory='charset = { file = "c.64c" }'), header=(0, 1)),
        Seed("screen RAM", "screen.bin", bytes(i & 0xFF for i in range(1000)),
             _vic("screen.bin", memory='screen = { file = "screen.bin" }')),
        Seed("Koala", "k.kla", _koala(), _vic("k.kla", memory='koala = "k.kla"'), header=(0, 1)),
        Seed("CharPad 5", "c5.ctm", _charpad(5), _vic("c5.ctm", memory='charpad = "c5.ctm"'), header=tuple(range(3, 24)),
             words=tuple(range(4, 24, 2))),
        Seed("CharPad 8", "c8.ctm", _charpad(8), _vic("c8.ctm", memory='charpad = "c8.ctm"'), header=tuple(range(3, 24)),
             words=tuple(range(4, 24, 2))),
        # NES graphics
        Seed("CHR", "g.chr", bytes(i * 5 & 0xFF for i in range(8192)), _nes(chr_file="g.chr")),
        Seed("CHR in iNES", "g.nes", _ines(), _nes(chr_file="g.nes"), header=tuple(range(4, 16)), words=(4, 8)),
        Seed("nametable", "n.nam", bytes(i % 7 for i in range(1024)), _nes(nametable="n.nam")),
        # the parry script
        Seed("parry script", "p.txt", b"4:parry 16:parry\n30:left 40:stop 52:parry\n",
             Target("parry", {}, ("parry", "--script", "@{dir}/{file}", "--frames", "60", "--out", "{dir}/out")),
             kind="text"),
        # symbol files (their parser is retro.loaders.symbols)
        Seed("ACME symbols", "p.sym", (foreign / "acme_boxhit.sym").read_bytes(),
             Target("run", {"p.prg": (foreign / "acme_boxhit.prg").read_bytes()},
                    ("run", "{dir}/p.prg", "--labels", "{dir}/{file}", "--entry", "$c000", "--budget", "20000"),
                    exit_1_allowed=True), kind="text"),
        Seed("ca65 debug file", "p.dbg", (foreign / "ca65_boxhit.dbg").read_bytes(),
             Target("run", {"p.prg": (foreign / "ca65_boxhit.prg").read_bytes()},
                    ("run", "{dir}/p.prg", "--labels", "{dir}/{file}", "--entry", "$c000", "--budget", "20000"),
                    exit_1_allowed=True), kind="text"),
    ]
    return found


# ---- mutations ---------------------------------------------------------------------------------

def _set(data: bytes, at: int, value: bytes) -> bytes:
    return data[:at] + value + data[at + len(value):]


def _byte_mutations(seed: Seed, rng: random.Random) -> Iterator[tuple[str, bytes]]:
    data = seed.data
    header_end = max(seed.header, default=1) + 1
    for cut in sorted({0, 1, 2, header_end - 1, header_end, header_end + 1, len(data) // 2, len(data) - 1}):
        if 0 <= cut < len(data):
            yield f"truncated to {cut} bytes", data[:cut]
    for _ in range(FLIPS_PER_SEED):
        at, bit = rng.randrange(len(data)), rng.randrange(8)
        yield f"bit {bit} of byte {at} flipped", _set(data, at, bytes([data[at] ^ (1 << bit)]))
    for _ in range(2):
        at = rng.randrange(len(data))
        value = rng.choice((0x00, 0xFF))
        yield f"byte {at} = ${value:02X}", _set(data, at, bytes([value]))
    for at in seed.header:
        if at < len(data):
            for value in (0x00, 0xFF, 0x80, 0x7F):
                yield f"header byte {at} = ${value:02X}", _set(data, at, bytes([value]))
    for at in seed.words:
        if at + 1 < len(data):
            for value in (0x0000, 0xFFFF, 0x8000):
                yield f"16-bit field at {at} = ${value:04X}", _set(data, at, struct.pack("<H", value))
    yield "64 KiB appended", data + bytes(rng.randrange(256) for _ in range(1024)) * 64
    yield "twice over", data * 2


def _text_mutations(seed: Seed, rng: random.Random) -> Iterator[tuple[str, bytes]]:
    text = seed.data.decode("utf-8")
    yield "UTF-16 with a byte order mark", text.encode("utf-16")
    at = rng.randrange(len(seed.data))
    yield f"a Latin-1 byte at {at}", _set(seed.data, at, b"\xe9")
    yield f"a NUL at {at}", seed.data[:at] + b"\0" + seed.data[at:]
    yield "a UTF-8 byte order mark", b"\xef\xbb\xbf" + seed.data
    yield "CR LF line ends", text.replace("\n", "\r\n").encode()
    digits = next((i for i, c in enumerate(text) if c.isdigit()), None)
    if digits is not None:
        yield "a 10,000-digit number", (text[:digits] + "9" * 10_000 + text[digits:]).encode()


def _toml_mutations(seed: Seed) -> Iterator[tuple[str, bytes, str]]:
    doc = tomllib.loads(seed.data.decode())
    marker = "@@FUZZ@@"
    for path in _paths(doc):
        template = toml_text(_replace(doc, path, marker))
        key = ".".join(map(str, path))
        last = next(str(p) for p in reversed(path) if not isinstance(p, int))
        for kind, value in WRONG_TYPES.items():
            yield f"{key} = {kind}", template.replace(toml_value(marker), value).encode(), last


def _json_paths(doc, prefix=()):
    if isinstance(doc, dict):
        for key, value in doc.items():
            yield prefix + (key,)
            yield from _json_paths(value, prefix + (key,))
    elif isinstance(doc, list):
        for i, value in enumerate(doc[:2]):  # the first two entries of a list stand for the rest
            if isinstance(value, (dict, list)):
                yield from _json_paths(value, prefix + (i,))


def _json_mutations(seed: Seed) -> Iterator[tuple[str, bytes, str]]:
    doc = json.loads(seed.data)
    for path in _json_paths(doc):
        last = next(str(p) for p in reversed(path) if not isinstance(p, int))
        for kind, value in JSON_WRONG_TYPES.items():
            copy = json.loads(seed.data)
            node = copy
            for step in path[:-1]:
                node = node[step]
            node[path[-1]] = value
            text = json.dumps(copy).replace('"HUGE"', HUGE_JSON_NUMBER)
            yield f"{'.'.join(map(str, path))} = {kind}", text.encode(), last


def cases(seed_numbers=SEEDS) -> Iterator[Case]:
    for seed in seeds():
        for number in seed_numbers:
            rng = random.Random(f"{number}:{seed.format}")
            for mutation, data in _byte_mutations(seed, rng):
                yield Case(seed, f"{mutation} (seed {number:#x})", data)
            if seed.kind in ("text", "toml", "json"):
                for mutation, data in _text_mutations(seed, rng):
                    yield Case(seed, f"{mutation} (seed {number:#x})", data)
        if seed.kind == "toml":
            for mutation, data, key in _toml_mutations(seed):
                yield Case(seed, mutation, data, key)
        if seed.kind == "json":
            for mutation, data, key in _json_mutations(seed):
                yield Case(seed, mutation, data, key)


if __name__ == "__main__":
    counts: dict[str, int] = {}
    for case in cases():
        counts[case.seed.format] = counts.get(case.seed.format, 0) + 1
    for name, count in counts.items():
        print(f"{count:6d}  {name}")
    print(f"{sum(counts.values()):6d}  in all")
