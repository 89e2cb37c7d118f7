"""Shared fixtures for the routine tests: one loaded runner per routine for the whole session."""

from __future__ import annotations

import pytest

from retro.routines.harness import RoutineRunner
from retro.routines.registry import ROUTINES, world_for


@pytest.fixture(scope="session")
def runners() -> dict[str, RoutineRunner]:
    return {name: RoutineRunner(routine, world_for(name)) for name, routine in ROUTINES.items()}
