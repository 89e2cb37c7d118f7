"""`retro optimize SPEC.toml`: a faster routine for a spec, proven equivalent on its domain
(docs/optimize.md): the new routine in the user's assembler syntax, the before/after costs, the
diff of the listings, the proof record and a spec for the new routine that `retro check` re-proves."""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import dataclass, replace

from retro.analysis.check import check_routine
from retro.commands import options
from retro.commands.check import failed
from retro.errors import InputError, RunError
from retro.fileio import all_or_nothing, output_folder, write_all_atomic
from retro.optimize.code import Listing, address_names, code_bytes
from retro.optimize.evaluate import PROOF_SPACE
from retro.optimize.optimizer import DEFAULT_WINDOW, OBJECTIVES, Options, Outcome, check_options, optimize as search
from retro.optimize.report import cost_row, cost_table, listing_diff, new_spec, toml_text
from retro.optimize.syntax import SYNTAXES, format_source, plain_lines
from retro.program import format_vice_labels, prg_bytes
from retro.numbers import parse_int
from retro.routines.spec import load_spec, read_spec_document
from retro.workers import MAX_WORKERS, SCHEDULER_ENV

SOURCE_SUFFIX = {"ca65": ".s", "ophis": ".oph", "kickass": ".asm", "dasm": ".asm", "xa": ".a65", "acme": ".a",
                 "64tass": ".asm"}


@dataclass
class Optimized:
    outcome: Outcome
    before: dict
    after: dict
    check: dict  # `retro check` of the new routine: cases, mismatches, engine, exhaustive
    proof: dict
    written: list
    source: str
    diff: list
    objective: str


def _labels(listing: Listing) -> dict[str, int]:
    address, at = listing.origin, {}
    for k, instruction in enumerate(listing.instructions):
        at[k] = address
        address += instruction.length
    at[len(listing.instructions)] = address
    return {name: at[i] for name, i in listing.labels}


@all_or_nothing
def optimize(spec: str, *, objective: str = "worst", no_slower: bool = False, budget: float = 30.0,
             window: int = DEFAULT_WINDOW, seed: int | None = None, preserve: tuple[str, ...] = (),
             syntax: str = "acme", out: str = "optimized", progress=None, jobs: int = 1,
             scheduler: str | None = None, smt: bool = True, tables: tuple[str, ...] = ()) -> Optimized:
    """Search for a faster routine for `spec`; every result is proven before it is reported. The
    search's work units run in this process (`jobs` 1), on `jobs` local Dask workers, or on the
    cluster at `scheduler` (retro.workers)."""
    opts = Options(objective, no_slower, budget, window, seed, tuple(p.upper() for p in preserve), jobs=jobs,
                   scheduler=scheduler, smt=smt, tables=tuple(tables))
    check_options(opts)
    if syntax not in SYNTAXES:
        raise InputError(f"--syntax: {syntax!r} is not one of {', '.join(SYNTAXES)}")
    routine = load_spec(spec)
    stem = f"{routine.name}_optimized"
    files = [stem + SOURCE_SUFFIX[syntax], stem + ".prg", stem + ".lbl", stem + ".toml", stem + ".diff"]
    folder = output_folder(out, files)
    outcome = search(routine, opts, progress)
    if outcome.program is None:
        raise RunError(f"{spec}: the new routine does not fit the old one's bytes (an internal error: never reported)")
    symbols = {n: a for n, a in routine.program.symbols.items()
               if not outcome.original.origin <= a < outcome.original.origin + code_bytes(outcome.original)
               or n in dict(outcome.original.labels) and n in dict(outcome.best.labels)}
    symbols.update(_labels(outcome.best))
    new_program = replace(outcome.program, symbols=symbols)  # labels moved with the code (loops' bounds too)
    moved = {routine.program.symbols[label]: symbols[label] for label in routine.loop_bounds
             if label in routine.program.symbols and label in symbols}
    new_routine = replace(routine, program=new_program, name=stem,
                          loop_addresses={moved.get(a, a): bound for a, bound in routine.loop_addresses.items()})
    exhaustive = routine.input_space() <= PROOF_SPACE
    checked = check_routine(new_routine, exhaustive=exhaustive, seed=outcome.routine.seed if seed is None else seed,
                            search_budget=0)
    if failed([checked]):
        raise RunError(f"{spec}: `retro check` refuses the new routine ({checked.mismatches} mismatches): nothing is "
                       f"reported (the search never admits a routine a check fails)")
    first, best = outcome.original_proof, outcome.best_proof
    before = cost_row(first.cycles["max"], first.cycles["mean"], first.cycles["min"], code_bytes(outcome.original),
                      routine.machine, outcome.table_bytes[0])
    after = cost_row(best.cycles["max"], best.cycles["mean"], best.cycles["min"], code_bytes(outcome.best),
                     routine.machine, outcome.table_bytes[1])
    original_names = address_names(routine.program.symbols)
    names = dict(original_names)
    for name, address in _labels(outcome.best).items():
        names[address] = name
    source = format_source(outcome.best, syntax, names, f"{routine.name}, optimised by retro optimize ({opts.objective})")
    diff = listing_diff(plain_lines(outcome.original, original_names), plain_lines(outcome.best, names), routine.name)
    doc = new_spec(read_spec_document(routine.spec_path), routine.spec_path.parent, folder.resolve(),
                   stem + ".prg", stem + ".lbl", stem)
    proof = {**best.record(), "check": {"cases": checked.totals.cases, "mismatches": checked.mismatches,
                                        "exhaustive": exhaustive, "engine": checked.engine},
             "optimal": ("none cheaper among the windows searched (every window of up to "
                         f"{opts.window} instructions over the pruned instruction set)" if outcome.complete else None)}
    outputs = {folder / files[0]: source, folder / files[1]: prg_bytes(new_program),
               folder / files[2]: format_vice_labels(symbols), folder / files[3]: toml_text(doc),
               folder / files[4]: "\n".join(diff) + "\n"}
    written = write_all_atomic(outputs)
    return Optimized(outcome, before, after, proof["check"], proof, [str(p) for p in written], source, diff,
                     opts.objective)


def lines(result: Optimized) -> list[str]:
    o = result.outcome
    out = [f"{o.routine.name}: objective {result.objective}; {len(o.changes)} change(s) in {o.seconds:.1f} s; "
           f"{o.tested:,} sequences tested, {o.routine_tests} routines run on the samples, {o.proofs} proofs "
           f"({o.failed_proofs} failed, {o.counterexamples} counterexamples added)"]
    out += cost_table(result.before, result.after, o.routine.machine)
    p = result.proof
    kind = {"exhaustive": "exhaustive: every input of the space",
            "smt": "smt: z3 proved every change equal on the outputs from every entry state in the domain, "
                   "and the spec's cases ran",
            "sampled": "sampled: random and boundary cases only"}
    out.append(f"proof: {kind.get(p['kind'], p['kind'])} ({p['cases']:,} cases, {p['calls']:,} calls on the "
               f"{p['engine']} engine, free entry state random per case); retro check: {p['check']['cases']:,} cases, "
               f"{p['check']['mismatches']} mismatches")
    for record in p.get("smt") or ():
        out.append(f"z3 ({record['scope']}): {record['status']} in {record['seconds']:.2f} s"
                   + (f" ({record['reason']})" if record["reason"] else ""))
    out.append(f"optimal: {p['optimal']}" if p["optimal"] else "optimal: not claimed (the budget ran out before every "
                                                                "window was searched)")
    out += result.diff or ["(no change)"]
    out.append("wrote " + ", ".join(result.written))
    return out


def as_json(result: Optimized) -> dict:
    o = result.outcome
    return {"routine": o.routine.name, "objective": result.objective, "before": result.before, "after": result.after,
            "changes": [{"at": c.start, "removed": len(c.removed), "added": len(c.added), "kind": c.kind}
                        for c in o.changes],
            "proof": result.proof, "tested": o.tested, "routine_tests": o.routine_tests, "proofs": o.proofs,
            "failed_proofs": o.failed_proofs, "seconds": round(o.seconds, 3), "smt_seconds": round(o.smt_seconds, 3),
            "source": result.source,
            "diff": result.diff, "written": result.written}


# The command line: this command's options and how it runs from them.

HELP = "search for a faster routine equivalent to a spec's, proven on its domain (docs/optimize.md)"


def add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", metavar="SPEC.toml", help="a routine spec with a reference (docs/specs.md)")
    p.add_argument("--objective", default="worst", help=f"what to minimise: {', '.join(OBJECTIVES)} (default worst; "
                                                        "the others break ties)")
    p.add_argument("--no-slower", action="store_true", help="never slower than the original on any input")
    p.add_argument("--budget", type=float, default=30.0, metavar="SECONDS", help="search time (default 30)")
    p.add_argument("--window", type=int, default=DEFAULT_WINDOW, metavar="N",
                   help=f"longest window of instructions replaced at once (default {DEFAULT_WINDOW})")
    p.add_argument("--seed", type=int, default=None, help="seed of the samples and entry states (default: the spec's)")
    p.add_argument("--preserve", default="", metavar="REGS",
                   help="registers and flags left as the original leaves them, e.g. X,Y,C (default: only the outputs)")
    p.add_argument("--tables", default="", metavar="NAMES",
                   help="[memory] blocks a candidate may read with an index, e.g. times3,sqr_lo (their bytes count)")
    p.add_argument("--no-smt", action="store_true",
                   help="past the sweep's reach, leave changes to the spec's cases (no z3 proof)")
    p.add_argument("--syntax", default="acme", help=f"source syntax: {', '.join(SYNTAXES)} (default acme)")
    options.out(p, "optimized")
    options.jobs(p, 1)
    options.scheduler(p)
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def main(args: argparse.Namespace) -> int:
    preserve = tuple(part.strip() for part in args.preserve.replace(" ", ",").split(",") if part.strip())
    tables = tuple(part.strip() for part in args.tables.split(",") if part.strip())
    result = optimize(args.spec, objective=args.objective, no_slower=args.no_slower, budget=args.budget,
                      window=args.window, seed=args.seed, preserve=preserve, syntax=args.syntax, out=args.out,
                      jobs=parse_int(args.jobs, field="--jobs", lo=1, hi=MAX_WORKERS),
                      scheduler=args.scheduler or os.environ.get(SCHEDULER_ENV) or None,
                      smt=not args.no_smt, tables=tables,
                      progress=lambda line: print(f"retro optimize: {line}", file=sys.stderr))
    options.show(lines, as_json if args.json else None, result, indent=1)
    return 0
