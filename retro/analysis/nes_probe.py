"""Probe cartridges: an NROM image that sets up a sprite-zero scene and reads $2002 once, after an
exact number of CPU cycles (asm/nes_sprite0_probe.s). Running such images in another emulator and
finding the first delay at which a flag is seen measures when that emulator sets it.

The program is assembled once; each image is a copy with the scene and the delay patched in.
"""

from __future__ import annotations

from functools import lru_cache

from retro.assembler import assemble_file
from retro.chips.ines import nrom_image
from retro.chips.ppu.constants import (
    CIRAM_SIZE,
    MIRRORING,
    NAMETABLE_BASE,
    NAMETABLE_SIZE,
    OAM_SIZE,
)
from retro.chips.ppu.state import PpuState
from retro.errors import InputError
from retro.paths import ASM_DIR
from retro.program import Program

PROBE_SOURCE = ASM_DIR / "nes_sprite0_probe.s"
RESULT_ADDRESS = 0x0010
DONE_ADDRESS = 0x0011
DONE_MARK = 0xA5
# Cycle costs of the delay routine's parts (JSR excluded, RTS included); see the source.
DELAY_BASE = 16                 # LDY abs, LDX abs, JMP (ind), RTS, and the fine loop's last BNE
DELAY_NO_COARSE = 7             # LDY abs + BEQ taken
DELAY_COARSE_BASE = 5           # LDY abs + BEQ not taken - the last outer BNE
DELAY_COARSE_STEP = 1256        # one outer iteration: LDX #250, 250 x (DEX, BNE) - 1, DEY, BNE
DELAY_FINE_STEP = 5             # DEX + BNE taken
DELAY_FINE_MAX = 256
DELAY_TAILS = 5                 # tails cost 2..6 cycles before their RTS
MIN_DELAY = DELAY_NO_COARSE + DELAY_BASE + DELAY_FINE_STEP
MAX_COARSE = 255


def delay_parameters(cycles: int) -> tuple[int, int, int]:
    """(delay_hi, delay_lo, tail) making the probe's delay routine take exactly `cycles`."""
    fine_span = DELAY_FINE_STEP * DELAY_FINE_MAX + DELAY_TAILS - 1
    if cycles < MIN_DELAY:
        raise InputError(f"delay {cycles} is below the probe's minimum of {MIN_DELAY} cycles")
    coarse = 0
    rest = cycles - DELAY_NO_COARSE - DELAY_BASE
    if rest > fine_span:
        coarse = -(-(cycles - DELAY_COARSE_BASE - DELAY_BASE - fine_span) // DELAY_COARSE_STEP)
        rest = cycles - DELAY_COARSE_BASE - DELAY_COARSE_STEP * coarse - DELAY_BASE
    if coarse > MAX_COARSE:
        raise InputError(f"delay {cycles} is beyond the probe's range")
    fine, tail = divmod(rest, DELAY_FINE_STEP)
    return coarse, fine % DELAY_FINE_MAX, tail


@lru_cache(maxsize=1)
def probe_program() -> Program:
    return assemble_file(PROBE_SOURCE)


def probe_image(state: PpuState, delay: int) -> bytes:
    """The iNES image of the probe for this scene, reading $2002 `delay` cycles into the delay routine."""
    if state.mirroring not in ("horizontal", "vertical"):
        raise InputError(f"probe: NROM has horizontal or vertical mirroring, not {state.mirroring!r}")
    program = probe_program()
    prg = bytearray(program.code)

    def put(label: str, data: bytes) -> None:
        offset = program.address_of(label) - program.origin
        prg[offset: offset + len(data)] = data

    put("scene_ciram", state.ciram[:CIRAM_SIZE])
    put("scene_oam", state.oam[:OAM_SIZE])
    put("ctrl", bytes([state.ctrl, state.mask, state.scroll_x, state.scroll_y]))
    second_page_logical = MIRRORING[state.mirroring].index(1)
    put("nametable1_high", bytes([(NAMETABLE_BASE + second_page_logical * NAMETABLE_SIZE) >> 8]))
    coarse, fine, tail = delay_parameters(delay)
    put("delay_hi", bytes([coarse, fine]))
    put("tail_vector", program.address_of(f"tail{tail}").to_bytes(2, "little"))
    return nrom_image(bytes(prg), state.chr, state.mirroring)
