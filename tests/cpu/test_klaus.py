"""Klaus Dormann's public 6502/65C02 functional tests (github.com/Klaus2m5/6502_65C02_functional_tests,
bin_files/): the 65C02 extended opcodes test on MPU65C02 and the 6502 functional test on the 6510.

Each prebuilt image is 64 KiB loaded at $0000 and started at its `code_segment` ($0400); a failed check
traps in a branch or JMP to itself, the success trap is the `jmp *` its listing marks "test passed, no
errors". Both the start and the success address are read from the listing shipped beside the image.
The files are not in the repository: they are read from ~/.cache/retro/klaus/ or the directory in
RETRO_KLAUS_TESTS (copy bin_files/*.bin and *.lst there); the tests skip, saying so, without them.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from retro.cpu.mpu import MPU6510
from retro.cpu.mpu65c02 import MPU65C02

CHUNK_CYCLES = 1_000_000
MAX_CYCLES = 150_000_000  # the 6502 test takes about 96 million, the 65C02 one about 67 million


def _directory() -> Path:
    return Path(os.environ.get("RETRO_KLAUS_TESTS") or Path.home() / ".cache" / "retro" / "klaus")


def _listed_address(listing: str, pattern: str) -> int:
    match = re.search(pattern, listing, re.MULTILINE)
    assert match, f"the listing has no line matching {pattern!r}"
    return int(match.group(1), 16)


def _trapped(mpu) -> bool:
    """The CPU loops on one instruction (a branch or JMP to itself): where the test stops on a failed check."""
    pc = mpu.pc
    mpu.step()
    return mpu.pc == pc


FULL = os.environ.get("RETRO_EXHAUSTIVE") == "1"
# The bounded form CI runs: the 65C02 test only (about 20 s; the 6502 vectors already prove the NMOS
# opcodes one by one); RETRO_EXHAUSTIVE=1 adds the 6502 functional test (about 50 s more).
TESTS = [("65C02_extended_opcodes_test", MPU65C02)] + ([("6502_functional_test", MPU6510)] if FULL else [])


@pytest.mark.exhaustive
@pytest.mark.parametrize("name, cpu_class", TESTS)
def test_klaus_dormann_functional_test_reaches_its_success_trap(name, cpu_class):
    directory = _directory()
    image, listing = directory / f"{name}.bin", directory / f"{name}.lst"
    if not image.is_file() or not listing.is_file():
        pytest.skip(f"no {name}.bin/.lst in {directory} (public: Klaus2m5/6502_65C02_functional_tests, bin_files/; "
                    f"set RETRO_KLAUS_TESTS to their directory)")
    text = listing.read_text(errors="replace")
    start = _listed_address(text, r"^([0-9a-f]{4}) =\s+code_segment\b")
    success = _listed_address(text, r"^([0-9a-f]{4}) : 4c[0-9a-f]{4}\s+>\s+jmp \*\s+;test passed, no errors")
    data = image.read_bytes()
    assert len(data) == 0x10000
    mpu = cpu_class(memory=list(data), pc=start)
    while mpu.processorCycles < MAX_CYCLES:
        mpu.run_until(success, -1, mpu.processorCycles + CHUNK_CYCLES)
        if mpu.pc == success:
            break
        assert not _trapped(mpu), (
            f"{name}: trapped at ${mpu.pc:04X} (test case {mpu.memory[0x0200]}) after {mpu.processorCycles} cycles")
    assert mpu.pc == success, f"{name}: not done after {MAX_CYCLES} cycles (PC ${mpu.pc:04X})"
