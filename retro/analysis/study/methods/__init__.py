"""The collision methods of the study: one object per method, one module per kind of method.

`BUILTIN` lists the study's own methods in the order the chart and the tables show them; a user's
method is a TOML file (methods/user.py, docs/methods.md) read by `load_methods`. Everything that
uses methods (evaluate, cost_runs, report, chart, stability, advisor) takes a sequence of these
objects and asks them; nothing switches on a method's key.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from retro.analysis.study.methods.base import Method, Session, sub_pair
from retro.analysis.study.methods.box import BOX, TIGHT, TIGHT_EDGES
from retro.analysis.study.methods.circle import CIRCLE, CIRCLE_R
from retro.analysis.study.methods.latch import LATCH
from retro.analysis.study.methods.pixel import PIXEL
from retro.analysis.study.methods.sat import SAT
from retro.analysis.study.methods.sprite_box import SPRITE_EDGES
from retro.analysis.study.methods.tile import TILE
from retro.errors import InputError

BUILTIN: tuple[Method, ...] = (BOX, TIGHT, TIGHT_EDGES, SPRITE_EDGES, CIRCLE, CIRCLE_R, TILE, PIXEL, LATCH, SAT)
METHODS = BUILTIN  # the default set of every command


def method(key: str, methods: Sequence[Method] = BUILTIN) -> Method:
    for m in methods:
        if m.key == key:
            return m
    raise KeyError(key)


def load_methods(paths: Iterable[str]) -> tuple[Method, ...]:
    """User methods from TOML files, each checked; a name already taken is an error naming the file."""
    from retro.analysis.study.methods.user import load_method_file

    taken = {m.key: m.origin for m in BUILTIN}
    loaded = []
    for index, path in enumerate(dict.fromkeys(str(p) for p in paths)):
        m = load_method_file(path, index)
        if m.key in taken:
            raise InputError(f"{path}: name: {m.key!r} is taken by {taken[m.key]} (give the method another name)")
        taken[m.key] = path
        loaded.append(m)
    return tuple(loaded)


def with_user_methods(paths: Iterable[str] | None, methods: Sequence[Method] = BUILTIN) -> tuple[Method, ...]:
    """The built-in methods followed by the user's."""
    return tuple(methods) + load_methods(paths or ())


__all__ = ["BOX", "BUILTIN", "CIRCLE", "CIRCLE_R", "LATCH", "METHODS", "PIXEL", "SAT", "SPRITE_EDGES", "TIGHT",
           "TIGHT_EDGES", "TILE", "Method", "Session", "load_methods", "method", "sub_pair", "with_user_methods"]
