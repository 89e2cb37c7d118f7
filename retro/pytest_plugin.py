"""pytest plugin (installed with the package): routine specs collected as test items.

Off until a project names its specs in pytest's own configuration, so it never collects a TOML
file nobody asked for:

    # pyproject.toml                               # or pytest.ini / tox.ini / setup.cfg
    [tool.pytest.ini_options]                      [pytest]
    retro_specs = ["specs/*.toml", "asm/**/*.toml"]  retro_specs = specs/*.toml asm/**/*.toml
    retro_engines = ["scalar", "batch"]            # optional: one item per spec and engine

`retro_specs` are glob patterns relative to the configuration file's folder (the rootdir without
one); every file they match is a routine spec (a file that is not one fails its item with the
one-line error `retro check` gives), and pytest collects it when it collects the folder it is in
(testpaths, or the paths given on the command line). A spec named on the command line is collected
whatever the patterns, once they are set. Each spec is one item (`specs/mul.toml::mul`, or
`mul[scalar]` and `mul[batch]` with two engines) marked `retro` (`pytest -m retro` runs only the
specs); it runs `retro check` on the spec and fails with the same report `retro check` prints.
`--retro-exhaustive` runs the full check (every exhaustive set and sweep). JUnit XML then comes from
pytest's own `--junitxml`: a failure element carrying the report (no per-item properties: the
default xunit2 schema has no place for them).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

SPECS_INI = "retro_specs"
ENGINES_INI = "retro_engines"
MARKER = "retro"
_MATCHED = pytest.StashKey[frozenset]()


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addini(SPECS_INI, type="args", default=[],
                  help="retro: glob patterns of routine specs to collect as tests (relative to the configuration "
                       "file's folder); none: the plugin collects nothing")
    parser.addini(ENGINES_INI, type="args", default=["auto"],
                  help="retro: the engines each spec runs on, one item per engine (auto, scalar, batch; default auto)")
    group = parser.getgroup("retro", "retro routine specs")
    group.addoption("--retro-exhaustive", action="store_true", default=False,
                    help="retro: run each collected spec's full check (every exhaustive set and sweep, the full "
                         "random count)")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", f"{MARKER}: a routine spec checked by retro (collected through {SPECS_INI})")
    from retro.analysis.check import ENGINES

    engines = config.getini(ENGINES_INI)
    wrong = [e for e in engines if e not in ENGINES]
    if wrong or not engines:
        raise pytest.UsageError(f"{ENGINES_INI}: {wrong[0] if wrong else 'no engine'!r} is not one of "
                                f"{', '.join(ENGINES)}")
    if len(set(engines)) != len(engines):
        raise pytest.UsageError(f"{ENGINES_INI}: an engine is named twice")


def _matched(config: pytest.Config) -> frozenset:
    """Every file the patterns match, resolved (globbed once per session)."""
    if _MATCHED not in config.stash:
        base = config.inipath.parent if config.inipath else config.rootpath
        found = set()
        for pattern in config.getini(SPECS_INI):
            if Path(pattern).is_absolute():
                anchor = Path(Path(pattern).anchor)
                matches = anchor.glob(str(Path(pattern).relative_to(anchor)))
            else:
                matches = base.glob(pattern)
            found.update(path.resolve() for path in matches if path.is_file())
        config.stash[_MATCHED] = frozenset(found)
    return config.stash[_MATCHED]


def pytest_collect_file(file_path: Path, parent: pytest.Collector):
    config = parent.config
    if not config.getini(SPECS_INI):
        return None
    if file_path.resolve() in _matched(config) or (parent.session.isinitpath(file_path)
                                                   and file_path.suffix.lower() == ".toml"):
        return SpecFile.from_parent(parent, path=file_path)
    return None


class SpecFile(pytest.File):
    """A routine spec: one item per engine."""

    def collect(self):
        engines = self.config.getini(ENGINES_INI)
        for engine in engines:
            name = self.path.stem if len(engines) == 1 else f"{self.path.stem}[{engine}]"
            yield SpecItem.from_parent(self, name=name, engine=engine)


class SpecItem(pytest.Item):
    """`retro check SPEC --engine ENGINE`: fails with the report on any mismatch or broken budget."""

    def __init__(self, *, engine: str, **kwargs) -> None:
        super().__init__(**kwargs)
        self.engine = engine
        self.add_marker(MARKER)

    def _shown(self) -> str:
        """The spec as its messages name it: relative to the working folder (as `retro check` would be
        given it there), which a test may have changed since pytest started."""
        try:
            return os.path.relpath(self.path, os.getcwd())
        except (ValueError, OSError):  # another drive, or the working folder is gone
            return str(self.path)

    def runtest(self) -> None:
        from retro.analysis.check import check_routine
        from retro.testing import RoutineFailed

        report = check_routine(self._shown(), exhaustive=self.config.getoption("retro_exhaustive"),
                               engine=self.engine, jobs=1)
        if report.mismatches:
            raise RoutineFailed(report)

    def repr_failure(self, excinfo, style=None):
        from retro.errors import RetroError
        from retro.testing import RoutineFailed

        if isinstance(excinfo.value, RoutineFailed):
            return str(excinfo.value)  # the report, as `retro check` prints it
        if isinstance(excinfo.value, RetroError):  # a bad spec: the one line `retro check` gives
            return f"retro check: {excinfo.value}"
        return super().repr_failure(excinfo, style=style)

    def reportinfo(self):
        return self.path, None, f"retro check {self._shown()} --engine {self.engine}"
