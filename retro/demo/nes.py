"""Demo step for the NES sprite-zero hit: predict the example scene, draw it, and poll it on the machine."""

from __future__ import annotations

from pathlib import Path

from retro.assembler import assemble_text
from retro.chips.ppu.clock import first_cycle_seeing
from retro.chips.ppu.constants import DOTS_PER_LINE
from retro.chips.ppu.hit import sprite_zero_hit
from retro.cpu import Machine
from retro.paths import EXAMPLES_DIR
from retro.render.images import save_png
from retro.render.nes_image import sprite_zero_image
from retro.scenes import load_scene

EXAMPLE = EXAMPLES_DIR / "nes_sprite0.toml"
POLL_LOOP = ".org $c000\nwait: bit $2002\n bvc wait\n rts\n"
POLL_EXIT_CYCLES = 2 + 6 + 1      # BVC not taken, RTS, and the BIT's read is its last cycle


def sprite_zero(out_dir: Path) -> list[str]:
    scene = load_scene(EXAMPLE)
    state = scene.ppu_state()
    result = sprite_zero_hit(state)
    save_png(sprite_zero_image(state, result, scale=2), out_dir / "nes_sprite0.png")
    machine = Machine(scene.cpu_variant)
    scene.attach(machine)
    program = machine.load(assemble_text(POLL_LOOP))
    run = machine.call(program.origin)
    read = run.cycles - POLL_EXIT_CYCLES
    visible = first_cycle_seeing(result.line * DOTS_PER_LINE + result.dot, origin=0, video=scene.video)
    return [f"examples/nes_sprite0.toml: hit at x={result.x}, line {result.line}; $2002 bit 6 set at dot "
            f"{result.dot}, {result.dots_after_vblank} dots after the vblank flag",
            f"`wait: bit $2002 / bvc wait` from frame start: the read that saw it was CPU cycle {read}, "
            f"{read - visible} cycles after the flag became visible (0-6 expected)",
            "wrote nes_sprite0.png"]
