"""Where `retro chart`'s time goes: each method's verdicts and its cycle measurement, one core.

    python benchmarks/study_speed.py [--shapes ball,ring,...] [--samples 192] [--all-cases]

For every method of the study: the seconds its verdict takes on every pair of the corpus (the
accuracy part of the chart), and the seconds its routine takes in py65 on `--samples` cases per pair
and, with --all-cases, on every case (the measured cycles). Beside them, the two costs issue 12
named, measured in this run against the way they were done before:
- SAT: retro.geometry.sat at every offset (each hull validated per call) against the study's SAT
  verdict (each hull validated once per pair, all offsets at once);
- the latch: the VIC-II frame of every offset of a pair (what the latch's cost session computed
  before, only to compare 192 of them) against the sampled offsets only.
"""

from __future__ import annotations

import argparse
import time
from itertools import combinations_with_replacement



def seconds(call) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    from retro.analysis.study.corpus import DEFAULT_SHAPES, load_shapes, make_pair
    from retro.analysis.study.cost_runs import _measure_pair, method_samples, sample_indices
    from retro.analysis.study.fits import pixel_hull
    from retro.analysis.study.latch import latch_verdicts
    from retro.analysis.study.methods import METHODS, SAT, sub_pair
    from retro.geometry.sat import sat

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shapes", default=",".join(DEFAULT_SHAPES))
    parser.add_argument("--samples", type=int, default=192, help="cases per pair of the sampled cost runs")
    parser.add_argument("--all-cases", action="store_true", help="also time the cost runs on every case")
    args = parser.parse_args(argv)

    shapes = load_shapes(args.shapes.split(","))
    jobs = list(combinations_with_replacement(shapes, 2))
    pairs = [make_pair(a, b) for a, b in jobs]
    cases = sum(p.cases for p in pairs)
    print(f"corpus: {len(shapes)} shapes, {len(pairs)} pairs, {cases} cases; one core")
    print(f"{'method':<14}{'verdicts s':>11}{f'cycles {args.samples}/pair s':>22}"
          + (f"{'cycles every case s':>21}" if args.all_cases else ""))
    for m in METHODS:
        verdict = seconds(lambda: [m.verdict(p) for p in pairs])
        line = f"{m.key:<14}{verdict:>11.2f}"
        if not m.host_only:
            line += f"{seconds(lambda: [_measure_pair(m, a, b, args.samples) for a, b in jobs]):>22.2f}"
            if args.all_cases:
                capped = method_samples(m, None)
                note = "" if capped is None else f" (capped at {capped}/pair)"
                line += f"{seconds(lambda: [_measure_pair(m, a, b, None) for a, b in jobs]):>21.2f}{note}"
        print(line, flush=True)

    def sat_per_offset() -> None:
        for p in pairs:
            ha, hb = pixel_hull(p.a.mask), pixel_hull(p.b.mask)
            for dx, dy in zip(p.dx.tolist(), p.dy.tolist()):
                sat(ha, [(x + dx, y + dy) for x, y in hb])

    once = seconds(lambda: [SAT.verdict(p) for p in pairs])
    every = seconds(sat_per_offset)
    print(f"SAT: hulls validated at every offset {every:.2f} s; once per pair, all offsets at once {once:.3f} s")
    sampled = [sub_pair(p, sample_indices(p, args.samples)) for p in pairs]
    full = seconds(lambda: [latch_verdicts(p) for p in pairs])
    few = seconds(lambda: [latch_verdicts(p) for p in sampled])
    print(f"latch: VIC-II frames of every offset {full:.2f} s; of the {args.samples} sampled offsets per pair "
          f"{few:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
