"""The CPU variants by the names users give them (a spec's `cpu`, `--cpu`): one class each."""

from __future__ import annotations

from retro.cpu.mpu import MPU2A03, MPU6510
from retro.cpu.mpu65c02 import MPU65C02
from retro.errors import InputError

VARIANTS = {"6510": MPU6510, "2a03": MPU2A03, "65c02": MPU65C02}


def variant_named(text: str, field: str) -> str:
    """A CPU variant as a user names it (any case: "65C02"), or a one-line error naming the field."""
    name = str(text).lower()
    if name not in VARIANTS:
        raise InputError(f"{field}: expected one of {', '.join(VARIANTS)}, got {text!r}")
    return name
