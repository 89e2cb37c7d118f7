"""`retro advise`: the cheapest method (in 6502 cycles) that meets an accuracy target on a scene's shapes.

The scene's sprites give the shapes: a VIC-II scene's enabled sprites (multicolor and expansion as the
scene sets them), an NES scene's OAM entries on screen (8x8 or 8x16, flips applied). Every unordered
pair of them is one shape pair of the study's corpus (all offsets where their boxes meet); identical
shape pairs are evaluated once and weighted by how many sprite pairs they stand for. Accuracy is
pooled over those cases (the counting rules of accuracy.py). Cycles are measured in the emulator on
the same pairs (the 2A03 runs these routines in the 6510's cycles: no decimal mode is used).

A method qualifies when its accuracy is at least the target, it has a 6502 cost, it exists on the
scene's machine (`Method.machines`: the VIC-II latch and the 9-bit sprite edges are the C64's) and
it can serve the scene (`Method.advice_note`: the hardware latch only with exactly two objects, since
with more its bits cannot say which pair collided; see the stability study's latch pitfalls).
`software` leaves the hardware methods out (more objects than sprites, or a game that must know which
pair hit). The NES's only collision hardware, the sprite-0 hit, tests sprite 0 against the background,
not sprites against each other: the advice says what it does in the scene and chooses among software
methods. With `objects` N the choice is by cycles per frame for N objects (per_frame.py: preparation,
the cheaper broad phase, the tests) against the scene's frame. SAT has no 6502 routine and is listed
only. A user's methods (`--method FILE.toml`) are compared alongside.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations

from retro.workers import Workers
from retro.analysis.study.accuracy import Confusion, pooled
from retro.analysis.study.corpus import Shape
from retro.analysis.study.costs import CycleStats
from retro.analysis.study.evaluate import evaluate
from retro.progress import Progress, quiet
from retro.analysis.study.methods import METHODS, Method
from retro.analysis.study.per_frame import ONCE, PAL_BUDGET, PHASE_LABELS, Budget, FrameRow
from retro.errors import InputError

ADVICE_COST_SAMPLES = 48


@dataclass(frozen=True)
class MethodFigures:
    key: str
    label: str
    counts: Confusion
    cycles: CycleStats
    qualifies: bool
    note: str
    frame: FrameRow | None = None  # with `objects`: the cost per frame, the cheaper broad phase


@dataclass(frozen=True)
class SceneObjects:
    machine: str  # "c64" or "nes"
    budget: Budget  # the scene's chip and standard
    shapes: list[tuple[int, Shape]]  # (sprite number, shape)
    hardware: str  # what the machine's collision hardware does in the scene (the NES's sprite-0 hit)


@dataclass(frozen=True)
class Advice:
    source: str
    sprites: list[int]
    sprite_pairs: int
    cases: float
    target: float
    figures: list[MethodFigures]  # cheapest first, unmeasured last
    chosen: MethodFigures | None
    runner_up: MethodFigures | None
    machine: str = "c64"
    budget: Budget = PAL_BUDGET
    objects: int | None = None  # advice by cost per frame for this many objects
    software: bool = False  # hardware methods left out
    notes: tuple[str, ...] = ()  # methods left out and why, the machine's collision hardware


def scene_shapes(path: str) -> list[tuple[int, Shape]]:
    """(sprite index, shape) for each enabled sprite of a VIC-II scene (at least two)."""
    from retro.analysis.study.sprites_io import scene_shapes as shapes_of_scene

    return shapes_of_scene(path, minimum=2)


def nes_shapes(scene) -> list[tuple[int, Shape]]:
    """(OAM entry, shape) for each entry of an NES scene drawn on screen with an opaque pixel: its
    pattern values as displayed (8x8 or 8x16, flips applied), value 0 transparent."""
    from retro.chips.ppu.constants import SCREEN_HEIGHT
    from retro.chips.ppu.pixels import sprite_values

    state = scene.ppu_state()
    out = []
    for number, _ in enumerate(scene.oam):
        top, _, values = sprite_values(state, number)
        mask = values != 0
        if top >= SCREEN_HEIGHT or not mask.any():
            continue  # below the visible lines, or transparent: it never collides
        out.append((number, Shape(name=f"sprite{number}", mask=mask, source=f"{scene.source} OAM entry {number}")))
    return out


def sprite_zero_note(scene) -> str:
    from retro.chips.ppu.hit import sprite_zero_hit

    hit = sprite_zero_hit(scene.ppu_state())
    seen = (f"here it is set for x {hit.x}, line {hit.line} ({hit.cpu_cycles_after_vblank:g} CPU cycles after vblank)"
            if hit.hit else f"here it is not set ({hit.reason})")
    return ("NES sprite-0 hit ($2002 bit 6): sprite 0 against opaque background pixels, once a frame; "
            f"{seen}. It never tests two sprites: the choice is among software methods")


def scene_objects(path: str) -> SceneObjects:
    """The scene's machine, frame budget, objects and collision hardware (VIC-II or NES scenes)."""
    from retro.analysis.study.per_frame import c64_budget, nes_budget
    from retro.scenes import load_scene
    from retro.scenes.nes import NesScene

    scene = load_scene(path)
    if isinstance(scene, NesScene):
        shapes = nes_shapes(scene)
        if len(shapes) < 2:
            raise InputError(f"{path}: oam: need at least 2 sprites on screen with opaque pixels (found {len(shapes)})")
        return SceneObjects("nes", nes_budget(scene.video), shapes, sprite_zero_note(scene))
    return SceneObjects("c64", c64_budget(scene.state.video), scene_shapes(path), "")


def _shape_key(shape: Shape) -> tuple:
    """Shapes that every method treats alike: the same opacity and the same display flags."""
    return shape.mask.shape, shape.mask.tobytes(), shape.data, shape.multicolor, shape.expand_x, shape.expand_y


def advise(path: str, target: float, workers: Workers | int | None = None, progress: Progress = quiet,
           samples: int = ADVICE_COST_SAMPLES, methods: tuple[Method, ...] = METHODS, software: bool = False,
           objects: int | None = None, engine: str = "auto") -> Advice:
    """`target` in (0, 1] and `objects` in 1..MAX_OBJECTS are checked by retro.commands.advise."""
    from retro.analysis.study.cost_runs import measure_costs

    scene = scene_objects(path)
    methods, notes = _usable_methods(scene, methods, software)
    indexed = scene.shapes
    weights, jobs = _pair_jobs(indexed)
    keys = list(jobs)
    table = evaluate([], methods, workers=workers, progress=progress, pair_list=[jobs[k] for k in keys])
    costs = measure_costs([], samples=samples, workers=workers, progress=progress, pair_list=[jobs[k] for k in keys],
                          methods=methods, engine=engine)
    sprite_count = len(indexed) if objects is None else objects
    frames = {}
    if objects is not None:
        from retro.analysis.study.per_frame import best_phase, per_frame

        model = per_frame(methods, {k: c.overall for k, c in costs.items()}, [s for _, s in indexed], counts=(objects,),
                          budget=scene.budget, workers=workers, progress=progress, engine=engine)
        frames = {m.key: best_phase(model.rows, m.key, objects) for m in methods}
    figures = []
    for m in methods:
        counts = pooled([_scaled(p.counts[m.key], weights[k]) for p, k in zip(table.pairs, keys)])
        cycles = costs[m.key].overall if m.key in costs else CycleStats.of([])
        qualifies, note = _verdict(m, counts.accuracy >= target, cycles, costs, sprite_count, objects, frames)
        figures.append(MethodFigures(m.key, m.label, counts, cycles, qualifies, note, frames.get(m.key)))
    figures.sort(key=_cost_order)
    eligible = [f for f in figures if f.qualifies]
    return Advice(source=str(path), sprites=[n for n, _ in indexed], sprite_pairs=sum(weights.values()),
                  cases=figures[0].counts.cases, target=target, figures=figures,
                  chosen=eligible[0] if eligible else None, runner_up=eligible[1] if len(eligible) > 1 else None,
                  machine=scene.machine, budget=scene.budget, objects=objects, software=software, notes=tuple(notes))


def _usable_methods(scene: SceneObjects, methods: tuple[Method, ...],
                    software: bool) -> tuple[tuple[Method, ...], list[str]]:
    """The methods that exist on the scene's machine (without the hardware ones with `software`),
    and notes saying which were left out and why."""
    notes = []
    absent = [m for m in methods if scene.machine not in m.machines]
    if absent:
        notes.append(f"not on the {scene.machine.upper()}: " + ", ".join(m.label for m in absent))
    methods = tuple(m for m in methods if scene.machine in m.machines)
    if software:
        left_out = [m for m in methods if m.hardware]
        if left_out:
            notes.append("--software: left out " + ", ".join(m.label for m in left_out))
        methods = tuple(m for m in methods if not m.hardware)
    if scene.hardware:
        notes.append(scene.hardware)
    return methods, notes


def _pair_jobs(indexed: list[tuple[int, Shape]]) -> tuple[dict[tuple, int], dict[tuple, tuple[Shape, Shape]]]:
    """Identical shape pairs (same data and flags, either order) are one job with a weight."""
    weights: dict[tuple, int] = {}
    jobs: dict[tuple, tuple[Shape, Shape]] = {}
    for (_, a), (_, b) in combinations(indexed, 2):
        key = tuple(sorted((_shape_key(a), _shape_key(b)), key=repr))
        weights[key] = weights.get(key, 0) + 1
        jobs.setdefault(key, (a, b))
    return weights, jobs


def _verdict(m: Method, accurate: bool, cycles: CycleStats, costs: dict, sprite_count: int, objects: int | None,
             frames: dict) -> tuple[bool, str]:
    """Whether a method qualifies, and the note saying why not (or what its cost leaves out)."""
    unusable = m.advice_note(sprite_count)
    if m.host_only or cycles.samples == 0:
        return False, costs[m.key].counted if m.key in costs else "no 6502 cost"
    if unusable:
        return False, unusable
    if objects is not None and frames.get(m.key) is None:
        return False, f"cannot serve {objects} objects"
    if not accurate:
        return False, "below the target"
    if m.prepare and objects is None:
        return True, f"per test; {m.prepare} once per {m.prepare_per.replace('_', ' ')} besides"
    return True, ""


def _cost_order(f: MethodFigures) -> tuple:
    """Cheapest first (per frame when there is a frame cost, else per test); no cost last."""
    if f.frame is not None:
        return (0, f.frame.frame_cycles)
    if math.isnan(f.cycles.mean):
        return (2, 0.0)
    return (1, f.cycles.mean)


def _scaled(c: Confusion, weight: int) -> Confusion:
    return Confusion(c.tp * weight, c.fp * weight, c.tn * weight, c.fn * weight)


def _describe(f: MethodFigures, budget: Budget = PAL_BUDGET) -> str:
    c = f.counts
    cycles = ("no 6502 cost" if math.isnan(f.cycles.mean)
              else f"{f.cycles.mean:.1f} cycles per test ({f.cycles.min}-{f.cycles.max})")
    if f.frame is not None:
        r = f.frame
        parts = [f"{r.frame_cycles:,.0f} cycles per frame for {r.objects} objects ({PHASE_LABELS[r.phase]}"]
        if r.prepare_calls:
            parts.append(f", {r.prepare_calls} prepare calls {r.prepare_cycles:,.0f}")
        if r.phase != ONCE:
            parts.append(f", {r.candidates:.1f} pairs tested")
        parts.append(f"; {100 * r.frame_cycles / float(budget.frame_cycles):.1f}% of a {budget.label} frame, worst "
                     f"{r.frame_worst:,.0f}), {cycles}")
        cycles = "".join(parts)
    return (f"{f.label}: {cycles}, accuracy {100 * c.accuracy:.2f}% "
            f"(FP rate {100 * c.fp_rate:.2f}%, FN rate {100 * c.fn_rate:.2f}%)")


def _fits(f: MethodFigures, budget: Budget) -> str:
    r = f.frame
    frame, lines = float(budget.frame_cycles), float(budget.lines_cycles)
    if r.frame_worst <= lines:
        return f"fits in {budget.lines} raster lines ({lines:,.0f} cycles) even at worst"
    if r.frame_cycles <= lines:
        return f"fits in {budget.lines} raster lines typically, in the frame at worst" if r.frame_worst <= frame else \
            f"fits in {budget.lines} raster lines typically; at worst over the frame ({frame:,.0f})"
    if r.frame_worst <= frame:
        return f"fits in the frame ({frame:,.0f} cycles) even at worst, not in {budget.lines} raster lines"
    if r.frame_cycles <= frame:
        return f"fits in the frame typically ({frame:,.0f} cycles), not at worst"
    return f"does not fit in a frame ({frame:,.0f} cycles)"


def advice_lines(advice: Advice) -> list[str]:
    objects = "" if advice.objects is None else f"; {advice.objects} objects per frame (the sprites in turn)"
    lines = [f"scene {advice.source} ({advice.budget.label}): sprites {', '.join(map(str, advice.sprites))} "
             f"({advice.sprite_pairs} sprite pairs, {advice.cases:.0f} cases); target accuracy "
             f"{100 * advice.target:.2f}%{objects}"]
    lines += [f"  note: {n}" for n in advice.notes]
    for f in advice.figures:
        mark = "ok " if f.qualifies else "-- "
        lines.append(f"  {mark}{_describe(f, advice.budget)}" + (f"  [{f.note}]" if f.note else ""))
    if advice.chosen is None:
        best = max(advice.figures, key=lambda f: f.counts.accuracy if not math.isnan(f.cycles.mean) else -1)
        lines.append(f"advice: no method with a 6502 cost meets {100 * advice.target:.2f}%; "
                     f"the most accurate is {_describe(best, advice.budget)}")
    else:
        lines.append(f"advice: {_describe(advice.chosen, advice.budget)}")
        if advice.chosen.frame is not None:
            lines.append(f"budget: {_fits(advice.chosen, advice.budget)}")
        lines.append(f"runner-up: {_describe(advice.runner_up, advice.budget)}" if advice.runner_up
                     else "runner-up: none (no other method meets the target)")
    return lines
