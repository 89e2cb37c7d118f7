"""`retro demo`: the toolkit's main jobs on built-in examples, as a list of calls to the same command
functions the CLI calls. Each step returns the lines to print; every file goes into one folder."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from retro.chips.ppu.clock import first_cycle_seeing
from retro.chips.ppu.constants import DOTS_PER_LINE
from retro.commands import asm, chart, cycles, nes, parry, profile, run, vic
from retro.fileio import all_or_nothing, output_folder, write_atomic
from retro.machines.c64 import interrupt_budgets
from retro.paths import ASM_DIR, EXAMPLES_DIR
from retro.progress import quiet
import argparse
from retro.commands import options

DEMO_SUM = ASM_DIR / "demo_sum.s"
VIC_SCENE = EXAMPLES_DIR / "vic_two_balls.toml"
RASTER_PROGRAM, RASTER_SCENE = EXAMPLES_DIR / "raster_irq_250.s", EXAMPLES_DIR / "raster_irq_250.toml"
RASTER_DEADLINE = 260  # the line the example's handler must end before
NES_SCENE, NES_POLL = EXAMPLES_DIR / "nes_sprite0.toml", EXAMPLES_DIR / "nes_sprite0_poll.s"
NES_POLL_EXIT_CYCLES = 2 + 6 + 1  # after the read that saw the flag: BVC not taken, RTS, the BIT's last cycle
ROUTINE_RANDOM_CASES = 150
ROUTINE_EXHAUSTIVE_SAMPLE = 1_000  # cases of each exhaustive set (sampled): the demo stays a few seconds
CHART_SHAPES = ("ball", "bar")  # 3 pairs, 5781 cases: the full study is `retro chart`
CHART_SAMPLES = 16


def assemble_and_run(out: Path) -> list[str]:
    built = asm.asm(DEMO_SUM, output=out / "demo_sum.prg", labels=out / "demo_sum.lbl")
    report = run.run(out / "demo_sum.prg", "demo_sum", labels=out / "demo_sum.lbl", x=8)
    r = report.result
    return ["asm/demo_sum.s: " + asm.lines(built)[0],
            f"demo_sum(X=8) -> A=${r.a:02X} Y=${r.y:02X} (sum {r.a | r.y << 8}) in {r.cycles} cycles, "
            f"{r.instructions} instructions (JSR not included)"]


def latch_scene(out: Path) -> list[str]:
    return vic.lines(vic.vic(VIC_SCENE, png=out / "vic_two_balls.png"))


def raster_budget(out: Path) -> list[str]:
    report = run.run(RASTER_PROGRAM, "main", scene=RASTER_SCENE, trace=True)
    handler = interrupt_budgets(report.machine, report.result)[0]
    return ["examples/raster_irq_250.s on examples/raster_irq_250.toml (text and two sprites on screen):",
            f"the raster interrupt's handler ran from line {handler.start_line} cycle {handler.start_cycle} to line "
            f"{handler.end_line} cycle {handler.end_cycle}: {handler.cycles} cycles, {handler.stolen} stolen by the "
            f"VIC-II, {handler.lines} lines; ends before line {RASTER_DEADLINE}: "
            f"{'yes' if handler.ends_before(RASTER_DEADLINE) else 'no'}",
            "its profile (retro profile examples/raster_irq_250.s --entry main --scene ... --png):",
            *profile.lines(profile.profile(RASTER_PROGRAM, entry="main", scene=RASTER_SCENE,
                                           png=out / "raster_irq_profile.png"))]


def parry_sequence(out: Path) -> list[str]:
    result = parry.parry(out=out)
    counts = {k: sum(e.kind == k for e in result.events) for k in ("window", "parry", "hit", "whiff", "expired")}
    return [f"script: {result.script}",
            "events: " + " ".join(str(e) for e in result.events),
            ", ".join(f"{v} {k}" for k, v in counts.items()),
            f"wrote {result.files[0].name} ({len(result.states)} frames) and {len(result.files) - 2} event frames as PNG"]


def sprite_zero(out: Path) -> list[str]:
    predicted = nes.nes(NES_SCENE, png=out / "nes_sprite0.png")
    hit = predicted.hit
    polled = run.run(NES_POLL, "wait", scene=NES_SCENE)
    read = polled.result.cycles - NES_POLL_EXIT_CYCLES
    visible = first_cycle_seeing(hit.line * DOTS_PER_LINE + hit.dot, origin=0, video=predicted.scene.video)
    return nes.lines(predicted) + [
        f"examples/nes_sprite0_poll.s (`bit $2002 / bvc`) from frame start: the read that saw it was CPU cycle "
        f"{read}, {read - visible} cycles after the flag became visible (0-6 expected)"]


def routine_table(out: Path) -> list[str]:
    checks = cycles.cycles(None, random=ROUTINE_RANDOM_CASES, jobs=1, progress=quiet,
                           bounded_product=ROUTINE_EXHAUSTIVE_SAMPLE)
    write_atomic(out / "routine_cycles.json", json.dumps(cycles.as_json(checks), indent=1) + "\n")
    total = sum(c.totals.cases for c in checks)
    bad = sum(c.mismatches for c in checks)
    return cycles.lines(checks) + [
        f"{total} calls checked against the references and the timing model: {bad} mismatches "
        f"(full run: retro check --exhaustive)", "wrote routine_cycles.json"]


def speed_accuracy(out: Path) -> list[str]:
    return chart.lines(chart.chart(out / "chart", shapes=CHART_SHAPES, samples=CHART_SAMPLES, jobs=1))


STEPS: tuple[tuple[str, Callable[[Path], list[str]]], ...] = (
    ("Assemble and run a 6502 routine", assemble_and_run),
    ("VIC-II collision scene: $D01E/$D01F/$D019 and the overlap image", latch_scene),
    ("Raster budget: a collision check in a raster interrupt, bad lines and sprite DMA included, and its profile",
     raster_budget),
    ("Parry pipeline: padded AABB window, SAT contact, MTV knock-back", parry_sequence),
    ("NES sprite-zero hit: model, picture, polling loop", sprite_zero),
    ("Collision routines: cross-checked results and cycles", routine_table),
    ("Speed against accuracy: cycles and error rates of every collision method", speed_accuracy),
)


@all_or_nothing
def demo(out: str | Path = "retro-out", emit: Callable[[str], None] = print) -> Path:
    """Run every step, printing through `emit` as it goes; returns the output folder."""
    out = output_folder(Path(out))
    for title, step in STEPS:
        emit(f"== {title}")
        for line in step(out):
            emit(f"   {line}")
    emit(f"Output files are in {out.resolve()}")
    return out


# The command line: this command's options and how it runs from them.

HELP = "run the built-in examples; writes its files into one folder"


def add_options(p: argparse.ArgumentParser) -> None:
    options.out(p, "retro-out")


def main(args: argparse.Namespace) -> int:
    demo(args.out)
    return 0
