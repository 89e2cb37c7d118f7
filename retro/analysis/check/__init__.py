"""Cross-check a routine (a spec: built-in or the user's) against its reference, results and cycles.

For every case: the routine's outputs must equal the reference's (inside the spec's `where`
domain), and the measured cycle count must equal the independent timing model summed over the
executed path (retro.cpu.timing). Cases outside the domain are run too: their failures are what
shows each condition of the domain is needed, and a failure inside it is a mismatch. Measured
extremes must lie within the static best/worst case (retro.cpu.flow), and both within the spec's
cycle budget (`[cycles] max`) when it has one.

Cases are made lazily (retro.routines.cases), by the worker that runs them (retro.workers: Dask);
the first run failure (BRK, JAM, a runaway past `[cycles] limit`) stops the check and is reported
with its inputs.

Two engines run the calls: `Machine` (scalar, the reference, with the timing model on every call)
and the batched core (retro.cpu.batch: 65,536 cases at a time with numpy). `engine="auto"` takes the
batched core from AUTO_BATCH_CASES planned cases on; then the first AGREEMENT_PER_PART cases of every
part also run on `Machine` with the timing model, and the two engines must agree call for call
(outputs and cycles): a disagreement is a mismatch of kind "engine". The compiled engine
(retro.cpu.compiled, `engine="compiled"`, or "auto" from AUTO_COMPILED_CASES) is an array engine like
the batched core, held to Machine the same way; `engines.array_engine` says which one runs and why.

The check by job (docs/architecture.md draws its path): `engines` (either engine -> the same
`CallBlock`; the one engine rule `batched`; runners cached per worker), `reference` (the reference's
answers), `tally` (one tally for both engines: what counts as a mismatch, and where a statistic is
added), `verdicts` (static bounds, budget), `run` (a whole check: plan, workers, agreement),
`results` (`RoutineCheck`). The reports (text and JSON) live beside the commands that print them:
retro/commands/check.py and cycles.py.
"""

from retro.analysis.check.engines import (
    AGREEMENT_PER_PART,
    AUTO_BATCH_CASES,
    ENGINES,
    SceneStart,
    batched,
    check_engine,
)
from retro.analysis.check.reference import reference_answers, expected_outputs
from retro.analysis.check.results import Failure, PartRun, RoutineCheck, describe_case, inputs_by_name
from retro.analysis.check.tally import Tally
from retro.analysis.check.run import check_routine, run_checks
from retro.analysis.check.verdicts import static_bounds

__all__ = ["AGREEMENT_PER_PART", "AUTO_BATCH_CASES", "ENGINES", "Failure", "PartRun", "RoutineCheck",
           "SceneStart", "check_routine", "describe_case", "batched", "check_engine", "reference_answers", "expected_outputs",
           "inputs_by_name", "run_checks", "static_bounds", "Tally"]
