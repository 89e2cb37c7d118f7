"""Packaging beside pyproject.toml: the data folders at the top of the repository (asm/, examples/,
sprites/: the layout users read) ship inside the wheel as retro/_data/asm, retro/_data/examples
and retro/_data/sprites (side by side, as the examples refer to ../sprites), so a non-editable `pip install .` has the built-in routines, specs and demo scenes
(retro/paths.py finds them in either place)."""

from setuptools import find_packages, setup

DATA_DIRS = {"retro._data.asm": "asm", "retro._data.examples": "examples", "retro._data.sprites": "sprites"}
DATA_FILES = {"retro._data.asm": ["*.s", "*.toml", "broad/*.s", "broad/*.toml"],
              "retro._data.examples": ["*.toml", "*.s"],
              "retro._data.sprites": ["*.spr", "*.png", "*.md"]}

setup(packages=find_packages(include=["retro", "retro.*"]) + list(DATA_DIRS), package_dir=DATA_DIRS,
      package_data=DATA_FILES)
