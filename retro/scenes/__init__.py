"""Scene files (TOML): the state one frame of a chip needs, and nothing more.

`load_scene(path)` reads the TOML, looks at its `chip` key and hands the document to the module for
that chip (`retro.scenes.vic` for "vic-ii", `retro.scenes.nes` for "nes"), which validates it into
plain dataclasses. Every scene object has a `cpu_variant` field ("6510" or "2a03"). A scene only
says what the chip holds; `retro.machines.build_machine(scene)` puts the chip on a machine's bus.
"""

from __future__ import annotations

from pathlib import Path

from retro.errors import InputError
from retro.fields import describe
from retro.fileio import parse_toml, read_bytes

CHIPS = ("vic-ii", "nes")  # the `chip` key of a scene file
# a scene that spells out every cell of four nametables and 512 tiles is about 200 KB
MAX_SCENE_BYTES = 1 << 20


def read_toml(path: str | Path) -> dict:
    return parse_toml(read_bytes(path, "scene file", MAX_SCENE_BYTES), str(path))


def load_scene(path: str | Path):
    doc = read_toml(path)
    chip = doc.get("chip")
    if not isinstance(chip, str) or chip not in CHIPS:
        raise InputError(f"{path}: chip: expected one of {', '.join(repr(c) for c in CHIPS)}, got {describe(chip)}")
    from retro.scenes import nes, vic  # here, not at the top: both use this package's helpers

    parse = {"vic-ii": vic.parse, "nes": nes.parse}[chip]
    return parse(doc, source=str(path))


def earlier_spelling(seen: dict, canonical, spelling: str) -> str | None:
    """The key that already named `canonical` (e.g. "$d011" before "d011", "0:3" before "0:03"), or
    None; records `spelling` as the first. Scenes reject a second spelling: the last one would win."""
    earlier = seen.get(canonical)
    seen.setdefault(canonical, spelling)
    return earlier
