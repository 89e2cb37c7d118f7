"""Shared by every test: the compiled engine's disk cache in one temporary folder for the session (each
routine compiles once per run, never into the user's ~/.cache)."""

from __future__ import annotations

import os

import pytest


@pytest.fixture(scope="session", autouse=True)
def compiled_cache(tmp_path_factory):
    """RETRO_CACHE for the session: routines compiled by one test load from the cache in the next."""
    folder = tmp_path_factory.mktemp("retro-cache")
    before = os.environ.get("RETRO_CACHE")
    os.environ["RETRO_CACHE"] = str(folder)
    yield folder
    if before is None:
        os.environ.pop("RETRO_CACHE", None)
    else:
        os.environ["RETRO_CACHE"] = before
