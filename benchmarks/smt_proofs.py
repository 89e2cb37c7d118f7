"""How fast z3 proves a change (retro.optimize.smt, docs/optimize.md "SMT proofs"), beside the
batched core's exhaustive sweep of the same routine where one is possible: CPU seconds per proof
and the ratio. The pairs are the docs' results: |A - m| (the textbook routine and the better one,
branches joined), sum3's store-and-load to a transfer, two independent instructions of aabb8
swapped (30 instructions, 5 branches, 2^64 inputs), a wasteful aabb8's branch over a JMP made one
branch (the JMP an edge z3 follows), and times3's table lookup (256 table bytes
assumed).

    PYTHONPATH=. python benchmarks/smt_proofs.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from retro.optimize.code import Instruction, Listing, assemble, read_listing
from retro.optimize.evaluate import PROOF_SPACE, Prover, scratch_of
from retro.optimize.flow import rewrites
from retro.optimize.formal import Formal
from retro.optimize.optimizer import direct_addresses, live_at_return
from retro.routines.spec import load_spec

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "optimize"


def _pairs():
    absdiff = load_spec(EXAMPLES / "absdiff.toml")
    old = read_listing(absdiff.program, absdiff.entry_address, absdiff.cpu)
    m = old.instructions[1].operand
    better = Listing(old.origin, (Instruction("CMP", "zpg", m), Instruction("SBC", "zpg", m),
                                  Instruction("BCS", "rel", None, "done"), Instruction("EOR", "imm", 0xFF),
                                  Instruction("RTS", "imp")), (("absdiff", 0), ("done", 4)))
    yield "absdiff: textbook -> CMP/SBC/BCS/EOR", absdiff, old, better
    sum3 = load_spec(EXAMPLES / "sum3.toml")
    old = read_listing(sum3.program, sum3.entry_address, sum3.cpu)
    yield "sum3: STX t / LDA t -> TXA", sum3, old, old.with_window(0, 2, (Instruction("TXA", "imp"),))
    aabb8 = load_spec(ROOT / "asm" / "aabb8.toml")
    old = read_listing(aabb8.program, aabb8.entry_address, aabb8.cpu)
    yield "aabb8 (5 branches): EOR / CLC swapped", aabb8, old, old.with_window(8, 10, old.instructions[9:7:-1])
    aabb8_jmp = load_spec(ROOT / "tests" / "optimize" / "wasteful" / "aabb8_jmp.toml")
    old = read_listing(aabb8_jmp.program, aabb8_jmp.entry_address, aabb8_jmp.cpu)
    yield "aabb8_jmp: BCC over JMP -> BCS", aabb8_jmp, old, dict(rewrites(old))["a branch over a JMP inverted"]
    times3 = load_spec(EXAMPLES / "times3.toml")
    old = read_listing(times3.program, times3.entry_address, times3.cpu)
    table = times3.program.symbols["times3_table"]
    yield ("times3: shift and add -> table lookup", times3, old,
           old.with_window(0, 4, (Instruction("TAX", "imp"), Instruction("LDA", "abx", table))))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"{'change':<42}{'z3':>10}{'verdict':>10}{'sweep':>10}{'inputs':>28}{'z3 / sweep':>12}")
    for name, routine, old, new in _pairs():
        size = sum(i.length for i in old.instructions)
        prover = Prover(routine, routine.seed, scratch_of(routine, direct_addresses(routine, old)))
        runner = prover.baseline.runner
        formal = Formal(routine, runner.call_image, size, live_at_return(routine, ()), runner.memory_values)
        began = time.process_time()
        for _ in range(args.repeat):
            verdict = formal.prove(old, new)
        z3_seconds = (time.process_time() - began) / args.repeat
        sweep = "-"
        ratio = "-"
        if routine.input_space() <= PROOF_SPACE:
            code = assemble(new, routine.cpu)
            began = time.process_time()
            for _ in range(args.repeat):
                assert prover.prove(code, routine.entry_address).passed
            sweep_seconds = (time.process_time() - began) / args.repeat
            sweep, ratio = f"{sweep_seconds:.3f}", f"{z3_seconds / sweep_seconds:.2f}x"
        print(f"{name:<42}{z3_seconds:>10.3f}{verdict.result.status:>10}{sweep:>10}{routine.input_space():>28,}"
              f"{ratio:>12}")


if __name__ == "__main__":
    main()
