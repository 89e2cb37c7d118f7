"""Data flows one way: the packages and top-level modules of retro/ import only from their own block
of the diagram in docs/architecture.md or the blocks above it (the test reads the picture), never form
a cycle, and keep the rules the docs state within a block. Every import counts, also inside functions."""

from __future__ import annotations

import ast
import re
from collections import defaultdict
from pathlib import Path

RETRO = Path(__file__).resolve().parents[1] / "retro"
ARCHITECTURE = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"
# Rules within a block of the diagram, as docs/architecture.md states them in words
FORBIDDEN = {
    "cpu": {"fields"},  # the 6502 harness knows no TOML
    "geometry": {"cpu", "chips", "routines", "assembler", "tables", "loaders", "sprites"},
    "analysis": {"render"},
    "render": {"analysis"},
    "commands": {"testing"},
}


def diagram_blocks() -> list[set[str]]:
    """The blocks of the diagram in docs/architecture.md, from the top (lowest layer) down: each a
    set of package or module names (`retro/cpu/` -> "cpu", `retro/fileio.py, numbers.py` -> both)."""
    text = ARCHITECTURE.read_text()
    picture = text[text.index("```\n") + 4:]
    picture = picture[:picture.index("```")]
    blocks: list[set[str]] = [set()]
    for line in picture.splitlines():
        if line.strip() == "|":
            blocks.append(set())
        elif line.startswith("retro/"):
            first_column = re.split(r"\s{2,}", line)[0]
            for item in first_column.split(","):
                name = item.strip().removeprefix("retro/").removesuffix("/").removesuffix(".py")
                if name:
                    blocks[-1].add(name)
    return [b for b in blocks if b]


def table_rows() -> list[str]:
    """The modules the docs' table ("## Modules") names, as paths or patterns: `retro/x/a.py`, `b.py`
    after it in one cell (the same folder), `retro/x/gfx_*.py`, a package `retro/x/` for all of it."""
    text = ARCHITECTURE.read_text()
    named = []
    for line in text[text.index("## Modules"):].splitlines():
        if not line.startswith("| `"):
            continue
        folder = ""
        for item in re.findall(r"`([^`]+)`", line.split("|")[1]):
            if item.startswith("retro/"):
                folder = item if item.endswith("/") else item.rsplit("/", 1)[0] + "/"
                named.append(item)
            elif folder and item.endswith(".py"):
                named.append(folder + item)
    return named


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


def test_the_diagram_places_every_package_and_module():
    placed = set().union(*diagram_blocks())
    present = {p.name.removesuffix(".py") for p in RETRO.iterdir()
               if not p.name.startswith("_") or p.name == "__main__.py"
               if (p.suffix == ".py" and p.name != "__init__.py") or (p.is_dir() and (p / "__init__.py").exists())}
    assert present - placed == set(), "not in docs/architecture.md's diagram"
    assert placed - present == set(), "in the diagram but not in retro/"


def test_the_table_names_every_module():
    """Each module of retro/ has its row in docs/architecture.md's table (itself, a pattern, or its package)."""
    from fnmatch import fnmatch

    named = table_rows()
    modules = [path.relative_to(RETRO.parent).as_posix() for path in RETRO.rglob("*.py") if path.name != "__init__.py"]
    unnamed = [m for m in modules if not any(fnmatch(m, pattern) or (pattern.endswith("/") and m.startswith(pattern))
                                             for pattern in named)]
    assert unnamed == [], "no row in docs/architecture.md's module table"
    assert all("retro/routines/" + name in named for name in ("input_plan.py", "outputs.py", "world_spec.py")), named


def test_no_package_imports_one_from_a_block_below_it():
    level = {name: i for i, block in enumerate(diagram_blocks()) for name in block}
    edges = package_imports()
    upward = {source: sorted(t for t in targets if level.get(t, -1) > level.get(source, -1))
              for source, targets in edges.items()}
    assert not {k: v for k, v in upward.items() if v}, "imports against the diagram's order"


def test_the_rules_within_a_block_hold():
    edges = package_imports()
    found = {package: sorted(edges[package] & banned) for package, banned in FORBIDDEN.items() if edges[package] & banned}
    assert not found, found


def test_the_diagram_is_read_as_drawn():
    """The test reads the picture it enforces: a check that it finds the blocks the docs draw."""
    blocks = diagram_blocks()
    assert {"errors", "fileio", "program"} <= blocks[0] and blocks[-1] == {"cli", "__main__", "entry"}
    order = [next(i for i, b in enumerate(blocks) if name in b) for name in ("cpu", "chips", "scenes", "machines",
                                                                               "routines", "analysis", "commands")]
    assert order == sorted(order) and len(set(order)) == len(order)


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
    """Demo steps and scene kinds are plain imports (grep and "find usages" follow them): importlib
    appears only where a routine spec or method file names the user's own module, where the compiled
    engine loads the module it generated into its cache (a file, not project code), and in cli.py, which
    imports only the command a run names (its module is `retro.commands.<name>`, the names listed in
    cli.COMMANDS and checked against the package's files by test_commands)."""
    users = {path.relative_to(RETRO).as_posix() for path in RETRO.rglob("*.py") if "importlib" in path.read_text()}
    assert users == {"routines/spec.py", "cpu/compiled.py", "cli.py"}, users
