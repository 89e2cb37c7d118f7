"""Where the project's data folders are: asm/, examples/, sprites/ beside the retro package.

They live at the top of the repository (the layout users read), so `retro` is used from a clone
with `pip install -e .`, as the README says.
"""

from __future__ import annotations

from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parent.parent
ASM_DIR = PROJECT_ROOT / "asm"
EXAMPLES_DIR = PROJECT_ROOT / "examples"
SPRITES_DIR = PROJECT_ROOT / "sprites"
