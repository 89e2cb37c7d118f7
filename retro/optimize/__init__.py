"""The superoptimiser (docs/optimize.md): candidate routines as plain data, their evaluation on the
batched core with the entry state the spec leaves free randomised, peephole windows and small
synthesis by an enumerative search, and proofs on the whole routine."""
