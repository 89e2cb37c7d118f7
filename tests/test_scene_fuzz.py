"""Fuzz: random scene files, valid and invalid, through `retro vic` and `retro nes`. Each must give a
result (exit 0) or one line and exit 2: never a traceback."""

from __future__ import annotations

import contextlib
import io
import random
import shutil
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from retro.cli import main
from retro.fileio import toml_text
from retro.paths import SPRITES_DIR

SCALARS = [0, 1, 2, 7, 8, 24, 63, 100, 255, 256, 511, 512, 65535, -1, 10 ** 30, 1.5, True, "x", "$d000", "",
           "0x10", "%101", "#" * 24, "ball.spr", "missing.spr", ".", "ntsc", "pal", "horizontal", "$ff", "9" * 5000]
VIC_SPRITE = ["index", "x", "y", "enabled", "multicolor", "expand_x", "expand_y", "behind", "color", "data", "rows",
              "file", "frame"]
VIC_MEMORY = ["screen", "color", "charset", "bitmap", "idle"]
VIC_REGISTERS = ["$d015", "d011", "$d010", "$d01b", "$d012", "$d01a", "$d016", "53280", "$d400", "$d01e", "$D015"]
NES_PPU = ["ctrl", "mask", "scroll_x", "scroll_y", "mirroring"]
NES_OAM = ["x", "y", "tile", "attr"]


def _value(rng: random.Random, depth: int = 0):
    r = rng.random()
    if depth > 1 or r < 0.6:
        return rng.choice(SCALARS)
    if r < 0.8:
        return [_value(rng, depth + 1) for _ in range(rng.randint(0, 25))]
    return {str(rng.choice(SCALARS)): _value(rng, depth + 1) for _ in range(rng.randint(0, 3))}


def _table(rng: random.Random, keys: list[str], most: int = 4) -> dict:
    return {k: _value(rng) for k in rng.sample(keys, min(len(keys), rng.randint(0, most)))}


def _scene(rng: random.Random) -> dict:
    if rng.random() < 0.6:
        doc = {"chip": "vic-ii"}
        if rng.random() < 0.5:
            doc["video"] = rng.choice(["pal", "ntsc", rng.choice(SCALARS)])
        if rng.random() < 0.7:
            doc["registers"] = {rng.choice(VIC_REGISTERS): rng.choice(SCALARS) for _ in range(rng.randint(0, 4))}
        if rng.random() < 0.8:
            doc["sprite"] = [_table(rng, VIC_SPRITE, 6) for _ in range(rng.randint(0, 3))]
        if rng.random() < 0.4:
            doc["memory"] = _table(rng, VIC_MEMORY)
        return doc
    doc = {"chip": rng.choice(["nes", "nes", rng.choice(SCALARS)])}
    if rng.random() < 0.6:
        doc["ppu"] = _table(rng, NES_PPU)
    if rng.random() < 0.7:
        doc["oam"] = [_table(rng, NES_OAM) for _ in range(rng.randint(0, 3))]
    if rng.random() < 0.3:
        doc["chr"] = _table(rng, ["file", "tiles"])
    return doc


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.integers(0, 2 ** 32))
def test_random_scenes_give_a_result_or_one_line(tmp_path: Path, seed: int):
    rng = random.Random(seed)
    shutil.copy(SPRITES_DIR / "ball.spr", tmp_path / "ball.spr")
    doc = _scene(rng)
    path = tmp_path / "scene.toml"
    path.write_text(toml_text(doc))
    err = io.StringIO()
    command = "nes" if doc["chip"] == "nes" else "vic"
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main([command, str(path), "--json"])
    assert code in (0, 2), err.getvalue()
    if code == 2:
        assert err.getvalue().count("\n") == 1 and "Traceback" not in err.getvalue(), err.getvalue()


def test_deeply_nested_toml_is_one_line(tmp_path, capsys):
    path = tmp_path / "deep.toml"
    path.write_text('chip = "vic-ii"\nvideo = ' + "[" * 2000 + "]" * 2000 + "\n")
    assert main(["vic", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
