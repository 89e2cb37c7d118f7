"""PRG + VICE label files written by ACME, 64tass and ca65/ld65 (real output, tests/data/foreign)."""

from __future__ import annotations

from pathlib import Path

import pytest

from retro.commands.run import run as run_routine

FOREIGN = Path(__file__).resolve().parent / "data" / "foreign"


@pytest.mark.parametrize("assembler", ["acme", "64tass", "ca65"])
def test_routine_from_another_assembler_runs_by_its_labels(assembler):
    report = run_routine(FOREIGN / f"{assembler}.prg", "my_routine", labels=FOREIGN / f"{assembler}.lbl",
                         a=3, peeks=["result:2"])
    # my_routine: CLC, ADC #5, STA result, LDA #0, ADC #0, STA result+1, RTS
    assert report.peeks["result"] == [8, 0]
    assert report.result.cycles == 2 + 2 + 4 + 2 + 2 + 4 + 6
