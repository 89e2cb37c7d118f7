"""The hand-worked routine of the coverage report tests: `sumto` (tests/data/coverage/), run on the
rows X = 0, 1, 3, and what each of its instructions did, counted by hand from the source and the
MOS datasheet's cycle table (not from retro):

    $C000 LDA #0        X=0: 1 run, X=1: 1, X=3: 1                      3 runs, 2 cycles
    $C002 CPX #0        the same                                         3 runs, 2 cycles
    $C004 BEQ done      taken for X=0 (3 cycles), not for X=1, X=3 (2)   3 runs, taken 1, not taken 2
    $C006 CLC           once per turn of the loop: X=1 1, X=3 3          4 runs, 2 cycles
    $C007 ADC $C0FD,X   X=3 reads $C100 (page crossed: 5), else 4        4 runs, 4-5 cycles
    $C00A BCS over      never taken (sums 1, 3, 6)                       4 runs, taken 0, not taken 4
    $C00C DEX                                                            4 runs, 2 cycles
    $C00D BNE loop      taken X=3->2, 2->1 (3 cycles); not at X=1 twice  4 runs, taken 2, not taken 2
    $C00F RTS                                                            3 runs, 6 cycles
    $C010 LDA #$FF      never run
    $C012 RTS           never run

The worst case is X=3, 51 cycles: $C000 $C002 $C004, the loop's five instructions three times, $C00F
(19 instructions). Source lines: sumto.s has `lda #0` on line 4 through the second `rts` on line 14,
one instruction a line; sumto_acme.asm the same on lines 3 to 13."""

from __future__ import annotations

from pathlib import Path

from retro.analysis.coverage_model import CodeCoverage
from retro.cpu.machine import Machine

DATA = Path(__file__).resolve().parents[1] / "data" / "coverage"
ROWS = (0, 1, 3)  # the X of each row of sumto.toml
ENTRY = 0xC000
ADDRESSES = (0xC000, 0xC002, 0xC004, 0xC006, 0xC007, 0xC00A, 0xC00C, 0xC00D, 0xC00F, 0xC010, 0xC012)
RUNS = (3, 3, 3, 4, 4, 4, 4, 4, 3, 0, 0)
CYCLES = {0xC000: (2, 2), 0xC002: (2, 2), 0xC004: (2, 3), 0xC006: (2, 2), 0xC007: (4, 5), 0xC00A: (2, 2),
          0xC00C: (2, 2), 0xC00D: (2, 3), 0xC00F: (6, 6)}
LOOP = (0xC006, 0xC007, 0xC00A, 0xC00C, 0xC00D)

HAND = CodeCoverage(
    executed=dict(zip(ADDRESSES, RUNS)),
    taken={0xC004: 1, 0xC00A: 0, 0xC00D: 2},
    not_taken={0xC004: 2, 0xC00A: 4, 0xC00D: 2},
    cycles_min={address: low for address, (low, _) in CYCLES.items()},
    cycles_max={address: high for address, (_, high) in CYCLES.items()},
    worst_path=(0xC000, 0xC002, 0xC004) + LOOP * 3 + (0xC00F,),
    worst_cycles=51,
)
SOURCE_LINE = dict(zip(ADDRESSES, range(4, 15)))  # sumto.s
ACME_LINE = dict(zip(ADDRESSES, range(3, 14)))  # sumto_acme.asm


# The listing: each line's fields, as counted by hand (whitespace aside; the columns are checked below)
EXPECTED_LISTING_ROWS = [
    ["sumto:"],
    [">", "$C000", "A9", "00", "LDA", "#$00", "3", "2", "2", "sumto.s:4"],
    [">", "$C002", "E0", "00", "CPX", "#$00", "3", "2", "2", "sumto.s:5"],
    [">", "$C004", "F0", "09", "BEQ", "$C00F", "3", "1", "2", "2", "3", "sumto.s:6"],
    ["loop:"],
    [">", "$C006", "18", "CLC", "4", "2", "2", "sumto.s:7"],
    [">", "$C007", "7D", "FD", "C0", "ADC", "$C0FD,X", "4", "4", "5", "sumto.s:8"],
    [">", "$C00A", "B0", "04", "BCS", "$C010", "4", "0!", "4", "2", "2", "sumto.s:9"],
    [">", "$C00C", "CA", "DEX", "4", "2", "2", "sumto.s:10"],
    [">", "$C00D", "D0", "F7", "BNE", "$C006", "4", "2", "2", "2", "3", "sumto.s:11"],
    ["done:"],
    [">", "$C00F", "60", "RTS", "3", "6", "6", "sumto.s:12"],
    ["over:"],
    ["$C010", "A9", "FF", "LDA", "#$FF", "#####", "sumto.s:13"],
    ["$C012", "60", "RTS", "#####", "sumto.s:14"],
]


def expected_lcov(source: str, lines: dict[int, int], name: str = "sumto") -> str:
    """The record counted by hand: entry line, branches (taken, not taken), every line's runs."""
    line = lines.__getitem__
    return "".join(f"{text}\n" for text in [
        f"TN:{name}", f"SF:{source}", f"FN:{line(0xC000)},{name}", f"FNDA:3,{name}", "FNF:1", "FNH:1",
        f"BRDA:{line(0xC004)},0,0,1", f"BRDA:{line(0xC004)},0,1,2",
        f"BRDA:{line(0xC00A)},0,0,0", f"BRDA:{line(0xC00A)},0,1,4",
        f"BRDA:{line(0xC00D)},0,0,2", f"BRDA:{line(0xC00D)},0,1,2",
        "BRF:6", "BRH:5",
        *[f"DA:{line(address)},{runs}" for address, runs in zip(ADDRESSES, RUNS)],
        "LF:11", "LH:9", "end_of_record"])


def machine_coverage(program, entry: int, cases: list[dict], reachable: tuple[int, ...]) -> CodeCoverage:
    """Test-only: the same figures from the scalar Machine's trace of each call (each case is the
    registers of one call), to show the hand count and the emulator agree. `reachable`: the
    instructions the listing should show (those no case ran count 0)."""
    machine = Machine()
    machine.load(program)
    coverage = CodeCoverage(executed=dict.fromkeys(reachable, 0))
    for registers in cases:
        result = machine.call(entry, trace=True, **registers)
        one = CodeCoverage(worst_path=tuple(e.address for e in result.trace), worst_cycles=result.cycles)
        for step in result.trace:
            one.executed[step.address] = one.executed.get(step.address, 0) + 1
            if step.mode == "rel":
                into = one.taken if step.branch_taken else one.not_taken
                into[step.address] = into.get(step.address, 0) + 1
                other = one.not_taken if step.branch_taken else one.taken
                other.setdefault(step.address, 0)
            one.cycles_min[step.address] = min(one.cycles_min.get(step.address, step.cycles), step.cycles)
            one.cycles_max[step.address] = max(one.cycles_max.get(step.address, step.cycles), step.cycles)
        coverage = coverage.merge(one)
    return coverage
