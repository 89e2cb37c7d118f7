"""VICE's own VIC-II collision test programs (the VICE testprogs repository: VICII/spritecollisions,
spritex, spritey, split-tests/spritescan), run from their BASIC SYS line through `retro run`'s own function, each verdict
read from the result byte they write at $D7FF (VICE's testbench: $00 passed, $FF failed).

The programs are never in the repository: they are read from $RETRO_VICE_TESTPROGS or
~/.cache/retro/vice-testprogs (a checkout of the testprogs repository, or its VICII folders), and
every test skips, saying where it looked, when they are absent. Their references are the results of
real machines (the programs' readmes and tables). Programs the model does not pass are listed with
the reason (docs/vic.md, "VICE's test programs") and expected to fail strictly.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from retro.commands import run

FULL = os.environ.get("RETRO_EXHAUSTIVE") == "1"
ROOT = Path(os.environ.get("RETRO_VICE_TESTPROGS") or Path.home() / ".cache" / "retro" / "vice-testprogs")
RESULT = "$D7FF"
FRAMES = 600  # the testbench's limits are 10,000,000 cycles (509 PAL frames); spritey needs 513

PROGRAMS = [f"VICII/spritecollisions/{name}.prg" for name in (
    "sprite-sprite-hi-hi", "sprite-sprite-hi-mc", "sprite-sprite-mc-hi", "sprite-sprite-mc-mc",
    "sprite-gfx-hi-hi", "sprite-gfx-hi-mc", "sprite-gfx-mc-hi", "sprite-gfx-mc-mc",
    "sprite-sprite", "sprite-sprite-collision-cycle")] + ["VICII/spritey/spritey.prg", "VICII/spritex/testsuite.prg"]

NOT_YET: dict[str, str] = {}  # program -> why the model does not pass it (none now)
BOUNDED = {"VICII/spritecollisions/sprite-sprite-hi-mc.prg", "VICII/spritecollisions/sprite-gfx-mc-hi.prg",
           "VICII/spritecollisions/sprite-sprite-collision-cycle.prg"}

# spritex/testsuite's table (testsuite.tas, the PAL rows): each case's $D01E after the move, as a
# real C64 shows it ($81: sprites 0 and 7 collide)
SPRITEX_REFERENCE = [0x81, 0, 0x81, 0x81, 0x81, 0, 0, 0x81, 0, 0, 0, 0, 0x81, 0, 0, 0x81, 0x81, 0x81, 0x81, 0x81, 0,
                     0, 0, 0, 0, 0, 0x81, 0x81, 0x81]


def _program(name: str) -> Path:
    path = ROOT / name
    if not path.is_file():
        pytest.skip(f"VICE test program absent: {path} (set RETRO_VICE_TESTPROGS or check out the VICE testprogs "
                    f"repository into {ROOT})")
    return path


def _param(name: str):
    marks = [pytest.mark.xfail(strict=True, reason=NOT_YET[name])] if name in NOT_YET else []
    return pytest.param(name, id=name.split("/")[-1].removesuffix(".prg"), marks=marks)


@pytest.mark.exhaustive
@pytest.mark.parametrize("name", [_param(name) for name in PROGRAMS if FULL or name in BOUNDED])
def test_vice_program_passes_from_its_sys_line(name):
    report = run.run_c64_program(_program(name), frames=FRAMES, result=RESULT)
    lines = run.lines(report)
    assert report.verdict is not None and report.verdict.passed is True, lines
    assert any(line.startswith("verdict: ") and line.endswith("passed") for line in lines)


@pytest.mark.exhaustive
def test_spritex_cases_agree_with_the_real_machine():
    """Cases 2, 5, 8, 11-13 write sprite 0's X in the cycle its row starts (X 95 -> 96 / 94, 96 -> 95,
    97 -> 96): a started row keeps its old X, one not started starts at the new X or not at all
    (docs/vic.md, "A sprite X write within a line")."""
    report = run.run_c64_program(_program("VICII/spritex/testsuite.prg"), frames=FRAMES, result=RESULT,
                                 peeks=[f"$4000:{len(SPRITEX_REFERENCE)}"])
    (got,) = report.peeks.values()
    wrong = {i + 1 for i, (a, b) in enumerate(zip(got, SPRITEX_REFERENCE)) if a != b}
    assert wrong == set(), got


SPRITESCAN = "VICII/split-tests/spritescan/spritescan.prg"
SPRITESCAN_BUFFER = "$6F00"  # BUFFER..BUFFER_END ($6F00-$7FFF): the header and the $1000 bytes of results
SPRITESCAN_IDENT = 32  # the dumps' first 32 bytes name an older revision ("SPRITESCAN R01"); the program skips them
SPRITESCAN_DUMPS = ("dump6569.bin", "dump8565.bin")  # real machines: a PAL breadbox's 6569, a C64C's 8565R2


def test_spritescan_agrees_with_the_real_machines_dumps():
    """split-tests/spritescan from its SYS line, with CIA 1's timer A (its frame measurement) and the
    print routines it calls stood in for (retro.machines.c64_stubs): its own check against the 6569
    dump passes, and its whole result buffer equals both real-machine dumps byte for byte (but the
    revision name; the 6572 dump is of a PAL-N Drean, a chip retro does not model)."""
    path = _program(SPRITESCAN)
    dumps = {name: (path.parent / "dumps" / name).read_bytes() for name in SPRITESCAN_DUMPS}
    report = run.run_c64_program(path, frames=4000, result=RESULT,
                                 peeks=[f"{SPRITESCAN_BUFFER}:{len(dumps['dump6569.bin'])}"])
    (got,) = report.peeks.values()
    assert report.printed[2] == "TIMING:  63 CYCLES/LINE,  312 LINES"  # timer A: 63 cycles a line
    assert report.verdict.passed is True, run.lines(report)
    for name, dump in dumps.items():
        wrong = [i for i in range(SPRITESCAN_IDENT, len(dump)) if got[i] != dump[i]]
        assert wrong == [], f"{name}: {len(wrong)} bytes differ, first at +${wrong[0]:04X}"


def test_the_character_rom_is_refused_when_a_latch_needs_it():
    """sprite-gfx-collision-cycle reads $D01F over text drawn from the character ROM, which retro
    does not have: the run ends with the one-line error, never a guessed value."""
    if os.environ.get("RETRO_C64_CHARGEN"):
        pytest.skip("RETRO_C64_CHARGEN is set: the character ROM is available")
    path = _program("VICII/spritecollisions/sprite-gfx-collision-cycle.prg")
    with pytest.raises(Exception, match="character ROM .*RETRO_C64_CHARGEN"):
        run.run_c64_program(path, frames=FRAMES, result=RESULT)


GFX_CYCLE = "VICII/spritecollisions/sprite-gfx-collision-cycle.prg"
GFX_CYCLE_PASSES = [1, 1] + [0] * 38  # its table refpal: $D01F as the C64 and C64C read it, X $56 on


def test_sprite_gfx_collision_cycle_with_the_users_character_rom():
    """With the real character ROM (the user's image in RETRO_C64_CHARGEN) the program passes."""
    if not os.environ.get("RETRO_C64_CHARGEN"):
        pytest.skip("RETRO_C64_CHARGEN is not set: sprite-gfx-collision-cycle draws its background from the "
                    "character ROM (Commodore's, not in retro): set it to a 4096-byte image to run this test")
    report = run.run_c64_program(_program(GFX_CYCLE), frames=FRAMES, result=RESULT, peeks=["$0450:40"])
    assert report.verdict.passed is True, run.lines(report)
    assert list(report.peeks.values())[0] == GFX_CYCLE_PASSES


@pytest.mark.parametrize("row2, passes", [(0xFF, True), (0x00, False)])
def test_sprite_gfx_collision_cycle_depends_on_one_glyph_row_only(tmp_path, monkeypatch, row2, passes):
    """The program's only sprite pixel (sprite 0's first, at Y $34: raster line 53) runs over X $56-$7D,
    columns 7-12 of text row 0, which hold screen code 160 (reverse space): its $D01F depends on the
    character ROM only through glyph 160's row 2 (line 53 = 51 + 2 with YSCROLL 3). An image holding
    that row solid and nothing else passes, as the real ROM's solid reverse space does [Programmer's
    Reference Guide, appendix B]; everything solid but that row fails. Not the real ROM: see the test
    above for it."""
    image = bytearray(b"\xff" * 4096) if not passes else bytearray(4096)
    image[160 * 8 + 2] = row2
    path = tmp_path / "glyph160.bin"
    path.write_bytes(image)
    monkeypatch.setenv("RETRO_C64_CHARGEN", str(path))
    report = run.run_c64_program(_program(GFX_CYCLE), frames=FRAMES, result=RESULT, peeks=["$0450:40"])
    assert report.verdict.passed is passes, run.lines(report)
    if passes:
        assert list(report.peeks.values())[0] == GFX_CYCLE_PASSES
