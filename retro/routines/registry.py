"""Routines by name or by spec file: the built-in ones are the spec files in asm/ (NAME.toml beside
NAME.s), read by the same code as a user's spec. Adding a built-in routine is one source, one spec
and one reference function; nothing here names a routine.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from retro.errors import InputError
from retro.fileio import is_file
from retro.paths import ASM_DIR
from retro.routines.spec import Routine, load_spec

SPEC_SUFFIX = ".toml"


def builtin_names() -> list[str]:
    """The built-in routines (every spec in asm/), in the order `retro check` runs them."""
    return sorted(p.stem for p in ASM_DIR.glob(f"*{SPEC_SUFFIX}"))


def is_spec_path(text: str) -> bool:
    return text.lower().endswith(SPEC_SUFFIX) or "/" in text or "\\" in text


def spec_path(name_or_path: str) -> Path:
    """The spec file of a built-in name, or the path as given."""
    if is_spec_path(name_or_path):
        return Path(name_or_path)
    path = ASM_DIR / f"{name_or_path}{SPEC_SUFFIX}"
    if not is_file(path):
        known = ", ".join(builtin_names())
        raise InputError(f"unknown routine {name_or_path!r} (built-in: {known}; or give a spec file NAME.toml)")
    return path


def get(name_or_path: str) -> Routine:
    return load_spec(spec_path(name_or_path))


def select(names: Iterable[str] | None) -> list[str]:
    """Spec paths of the named routines (all built-ins when none are named), each once, in the order
    first named; every name is checked before any work starts."""
    names = list(dict.fromkeys(names or [])) or builtin_names()
    paths = [str(spec_path(n)) for n in names]
    for path in paths:
        load_spec(path)
    return list(dict.fromkeys(paths))
