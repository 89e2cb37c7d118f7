"""What each method costs: 6502 cycles measured in the emulator, bytes of code and tables, and host
microseconds of the Python reference. (Measurement code lives in cost_runs.py; this is the data.)"""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass(frozen=True)
class CycleStats:
    mean: float
    min: int
    max: int
    samples: int

    @staticmethod
    def of(values: list[int]) -> "CycleStats":
        if not values:
            return NO_CYCLES
        return CycleStats(mean=sum(values) / len(values), min=min(values), max=max(values), samples=len(values))


NO_CYCLES = CycleStats(mean=math.nan, min=0, max=0, samples=0)


@dataclass(frozen=True)
class MethodCost:
    """Cost of one method: cycles per test overall and per pair, bytes, host time, and what is counted."""

    key: str
    routine: str  # the 6502 entry measured ("" for host-only methods)
    overall: CycleStats
    per_pair: dict[str, CycleStats] = field(default_factory=dict)
    code_bytes: int | None = None
    table_bytes: int | None = None
    host_us: float = math.nan  # microseconds per test of the Python reference on this host
    counted: str = ""  # what the cycle figure covers
    prepare: str | None = None  # the once-per-object preparation routine (its cost is not in these cycles)

    def cycles_for(self, pair: str | None) -> CycleStats:
        if pair is None:
            return self.overall
        return self.per_pair.get(pair, self.overall)
