"""Shared fixtures for the routine tests: one loaded runner per built-in routine for the whole session."""

from __future__ import annotations

import pytest

from retro.routines.registry import builtin_names, get
from retro.routines.runner import RoutineRunner


@pytest.fixture(scope="session")
def runners() -> dict[str, RoutineRunner]:
    return {name: RoutineRunner(get(name)) for name in builtin_names()}
