"""Shared by the CPU tests: where the SingleStepTests vectors live, and a place to report figures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

VECTOR_ENV = "RETRO_CPU_VECTORS"
REPO_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_VECTOR_ROOT = REPO_ROOT.parent / "shared" / "cpu-vectors"

# Lines the vector tests add; printed at the end of the pytest run (the README quotes them).
FIGURES: dict[str, str] = {}


def vector_root() -> Path:
    return Path(os.environ.get(VECTOR_ENV) or DEFAULT_VECTOR_ROOT)


@pytest.fixture(scope="session")
def vector_dir() -> Path:
    """The directory of `XX.json.gz` files. Outside CI the tests skip when the vectors are not there at
    all; in CI (the CI variable set, as .ci/run's runner sets it, with ../shared beside the clone)
    missing vectors fail, so a green run always means the CPU was checked against them."""
    root = vector_root()
    if not root.exists():
        if os.environ.get("CI"):
            pytest.fail(f"no CPU test vectors at {root}: CI has ../shared/cpu-vectors, so this is an error")
        pytest.skip(f"no CPU test vectors at {root} (kept outside the repository; "
                    f"set {VECTOR_ENV} to the directory holding 6502/XX.json.gz)")
    directory = root / "6502" if (root / "6502").is_dir() else root
    assert any(directory.glob("*.json.gz")), f"{directory} exists but holds no XX.json.gz vector files"
    return directory


@pytest.fixture(scope="session")
def figures() -> dict[str, str]:
    return FIGURES


def pytest_terminal_summary(terminalreporter) -> None:
    for line in FIGURES.values():
        terminalreporter.write_line(line)
