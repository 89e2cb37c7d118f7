"""Shared small corpus for the study's tests: three sprite files and two hand-made masks."""

from __future__ import annotations

import numpy as np
import pytest

from retro.analysis.study.corpus import REDUCED_SHAPES, Shape, load_shapes


@pytest.fixture(scope="session")
def sprite_shapes() -> list[Shape]:
    return load_shapes(REDUCED_SHAPES)


def box_shape(name: str, x0: int, y0: int, x1: int, y1: int, width: int = 24, height: int = 21) -> Shape:
    mask = np.zeros((height, width), dtype=bool)
    mask[y0:y1, x0:x1] = True
    return Shape(name=name, mask=mask)


@pytest.fixture(scope="session")
def hand_shapes() -> list[Shape]:
    """A 4x4 block and a diagonal line of pixels: a concave-free and a very sparse shape."""
    diagonal = np.zeros((21, 24), dtype=bool)
    for i in range(0, 20, 2):
        diagonal[i, i] = True
    return [box_shape("block", 5, 6, 9, 10), Shape(name="diagonal", mask=diagonal)]
