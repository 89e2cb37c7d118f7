"""The foundation's demo step: assemble a sample routine, run it, show its cycle count."""

from __future__ import annotations

from pathlib import Path

from retro.assembler import assemble_file
from retro.cpu import Machine
from retro.fileio import write_atomic
from retro.paths import ASM_DIR
from retro.program import format_vice_labels, prg_bytes


def assemble_and_run(out_dir: Path) -> list[str]:
    program = assemble_file(ASM_DIR / "demo_sum.s")
    machine = Machine()
    machine.load(program)
    result = machine.call("demo_sum", x=8)
    total = result.a | result.y << 8
    write_atomic(out_dir / "demo_sum.prg", prg_bytes(program))
    write_atomic(out_dir / "demo_sum.lbl", format_vice_labels(program.symbols))
    return [f"asm/demo_sum.s: {len(program.code)} bytes at ${program.origin:04X}",
            f"demo_sum(X=8) -> A=${result.a:02X} Y=${result.y:02X} (sum {total}) in {result.cycles} cycles, "
            f"{result.instructions} instructions (JSR not included)",
            "wrote demo_sum.prg and demo_sum.lbl (VICE labels)"]
