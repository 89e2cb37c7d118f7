"""What the cases of a check ran of the routine's code: the plain data that both engines fill, that
merges across blocks and worker processes, and that every coverage report (text, JSON, the annotated
listing, LCOV, HTML) reads. Only data here: collecting it lives with the engines, rendering it with the
reports."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class CodeCoverage:
    """Per instruction address of the routine's code (every instruction reachable from its entry and
    init, 0 when no case ran it): how often it ran, and for conditional branches how often each way.
    `cycles_min`/`cycles_max`: the fewest and most cycles one execution of that instruction took (page
    and branch penalties included, stolen cycles not). `worst_path`: the instruction addresses, in
    order, that the case with the most cycles ran (empty when not recorded)."""

    executed: dict[int, int] = field(default_factory=dict)
    taken: dict[int, int] = field(default_factory=dict)
    not_taken: dict[int, int] = field(default_factory=dict)
    cycles_min: dict[int, int] = field(default_factory=dict)
    cycles_max: dict[int, int] = field(default_factory=dict)
    worst_path: tuple[int, ...] = ()
    worst_cycles: int | None = None

    def merge(self, other: "CodeCoverage") -> "CodeCoverage":
        """Both blocks' counts added, the extremes kept, the worse case's path kept (`self` itself when
        `other` holds nothing: a block of the compiled engine, which counts no coverage)."""
        if other.worst_cycles is None and not any((other.executed, other.taken, other.not_taken, other.cycles_min,
                                                   other.cycles_max, other.worst_path)):
            return self
        def added(a: dict[int, int], b: dict[int, int]) -> dict[int, int]:
            return {k: a.get(k, 0) + b.get(k, 0) for k in a.keys() | b.keys()}

        def extreme(a: dict[int, int], b: dict[int, int], pick) -> dict[int, int]:
            return {k: pick(v for v in (a.get(k), b.get(k)) if v is not None) for k in a.keys() | b.keys()}

        worse = other if (other.worst_cycles or -1) > (self.worst_cycles or -1) else self
        return CodeCoverage(added(self.executed, other.executed), added(self.taken, other.taken),
                            added(self.not_taken, other.not_taken), extreme(self.cycles_min, other.cycles_min, min),
                            extreme(self.cycles_max, other.cycles_max, max), worse.worst_path, worse.worst_cycles)
