"""Where the project's data folders are: asm/, examples/, sprites/.

In a clone (and with `pip install -e .`) they are the folders at the top of the repository, the
layout users read. A wheel (`pip install .`) carries them inside the package as retro/_data/asm,
retro/_data/examples and retro/_data/sprites (setup.py maps them); those are used when they exist.
What retro keeps between runs (compiled routines, assembled programs) lives under one cache folder.
"""

from __future__ import annotations

import os
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
PROJECT_ROOT = PACKAGE_DIR.parent


def _data_dir(name: str) -> Path:
    packaged = PACKAGE_DIR / "_data" / name
    return packaged if packaged.is_dir() else PROJECT_ROOT / name


ASM_DIR = _data_dir("asm")
EXAMPLES_DIR = _data_dir("examples")
SPRITES_DIR = _data_dir("sprites")

CACHE_ENV = "RETRO_CACHE"  # the cache folder's environment variable (default ~/.cache/retro)


def cache_dir(kind: str) -> Path:
    """The folder of one kind of cached data ("compiled", "assembled") under $RETRO_CACHE."""
    base = os.environ.get(CACHE_ENV)
    return (Path(base) if base else Path.home() / ".cache" / "retro") / kind
