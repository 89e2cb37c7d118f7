"""Data flows one way (docs/architecture.md): the packages of retro/ import each other without a cycle,
and the low layers import none of the high ones. Every import counts, also those inside functions."""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

RETRO = Path(__file__).resolve().parents[1] / "retro"
# package -> packages it must never import (the layers above it)
TOP = {"commands", "cli"}  # what each command does, and the command line: nothing below imports them
FORBIDDEN = {
    "cpu": {"chips", "machines", "scenes", "routines", "analysis", "render", "sprites", "loaders"} | TOP,
    "chips": {"machines", "scenes", "routines", "analysis", "render", "sprites", "loaders"} | TOP,
    "geometry": {"cpu", "chips", "routines", "analysis", "render", "scenes"} | TOP,
    "loaders": {"render", "analysis", "scenes", "routines", "sprites"} | TOP,
    "sprites": {"render", "analysis", "scenes", "routines"} | TOP,
    "routines": {"analysis", "render"} | TOP,
    "scenes": {"analysis", "render"} | TOP,
    "machines": {"analysis", "render"} | TOP,
    "analysis": TOP,
    "render": TOP,
    "commands": {"cli"},
}


def package_imports() -> dict[str, set[str]]:
    edges: dict[str, set[str]] = defaultdict(set)
    for path in RETRO.rglob("*.py"):
        relative = path.relative_to(RETRO)
        source = relative.parts[0].removesuffix(".py")
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([node.module] if isinstance(node, ast.ImportFrom) and node.module else
                     [a.name for a in node.names] if isinstance(node, ast.Import) else [])
            for name in names:
                parts = name.split(".")
                if parts[0] == "retro" and len(parts) > 1 and parts[1] != source:
                    edges[source].add(parts[1])
    return edges


def test_low_layers_import_no_high_ones():
    edges = package_imports()
    found = {package: sorted(edges[package] & banned) for package, banned in FORBIDDEN.items() if edges[package] & banned}
    assert not found, found


def test_the_packages_form_no_cycle():
    edges = package_imports()
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for target in sorted(edges.get(node, ())):
            if state.get(target) == 1:
                return path[path.index(target):] + [target]
            if target not in state:
                cycle = visit(target)
                if cycle:
                    return cycle
        path.pop()
        state[node] = 2
        return None

    for package in sorted(edges):
        if package not in state:
            cycle = visit(package)
            assert cycle is None, " -> ".join(cycle)


def test_importlib_only_loads_users_own_python_files():
    """Commands, demo steps and scene kinds are plain imports (grep and "find usages" follow them):
    importlib appears only where a routine spec or method file names the user's own module."""
    users = {path.relative_to(RETRO).as_posix() for path in RETRO.rglob("*.py") if "importlib" in path.read_text()}
    assert users == {"routines/spec.py"}, users
