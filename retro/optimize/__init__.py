"""The superoptimiser (docs/optimize.md): candidate routines as plain data, their evaluation on the
batched core with the entry state the spec leaves free randomised, peephole windows and small
synthesis by an enumerative search, tables the user allows, and proofs on the whole routine (a sweep,
or z3 past the sweep's reach)."""
