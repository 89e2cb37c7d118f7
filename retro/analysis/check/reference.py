"""The reference's answers for cases: one case at a time or a block of cases as arrays, in the
outputs' order, every answer checked against its output's width (a one-line error naming the case)."""

from __future__ import annotations

import numpy as np

from retro.analysis.check.results import describe_case
from retro.errors import InputError
from retro.routines import cases as case_sets
from retro.routines.sandbox import UserCodeError, shown
from retro.routines.spec import Routine
from retro.routines.world import reference_calls


def expected_outputs(routine: Routine, case: tuple, memory: dict, calls: dict | None = None) -> tuple:
    """The reference's answer for a case, as a tuple in the outputs' order (a one-line error for a
    reference that raises or answers in the wrong shape); `calls`: the mocks' calls it takes, by name."""
    arguments = dict(zip(routine.input_names, case))
    arguments.update({name: memory[name] for name in routine.reference_memory})
    arguments.update(calls or {})
    try:
        value = routine.reference(**arguments)
    except UserCodeError:  # a hang, an exit, a runaway: its own line, never a refusal
        raise
    except Exception as exc:  # the user's reference: whatever it raises is reported in one line
        raise InputError(f"{routine.spec_path}: reference {routine.reference_name} raised {type(exc).__name__}: "
                         f"{str(exc)[:200]} (inputs {describe_case(routine, case)})") from None
    return normalise_outputs(routine, value, case)


def normalise_outputs(routine: Routine, value, case: tuple) -> tuple:
    outputs = routine.outputs
    where = f"{routine.spec_path}: reference {routine.reference_name}"
    if isinstance(value, dict):
        if set(value) != set(routine.output_names):
            raise InputError(f"{where} returned keys {sorted(value)} for the outputs {list(routine.output_names)} "
                             f"(inputs {describe_case(routine, case)})")
        values = [value[name] for name in routine.output_names]
    elif len(outputs) == 1:
        values = [value]
    else:
        raise InputError(f"{where} returned {type(value).__name__}; with {len(outputs)} outputs it must return a "
                         f"dict {{{', '.join(routine.output_names)}}} (inputs {describe_case(routine, case)})")
    out = []
    for port, item in zip(outputs, values):
        out.append(_output_value(port, item, where, routine, case))
    return tuple(out)


def _output_value(port, item, where: str, routine: Routine, case: tuple):
    if isinstance(item, np.ndarray) and item.ndim == 0 or isinstance(item, np.generic):
        item = item.item()
    if port.table:
        try:
            values = tuple(int(v) for v in item)
        except (TypeError, ValueError):
            values = None
        if values is None or len(values) != len(port.places) or any(not 0 <= v <= 0xFF for v in values):
            raise InputError(f"{where} returned {shown(item)} for {port.name}: expected {len(port.places)} bytes "
                             f"(inputs {describe_case(routine, case)})")
        return values
    if isinstance(item, bool):
        item = int(item)
    limit = 1 << port.bits
    if not isinstance(item, int) or not 0 <= item < limit:
        raise InputError(f"{where} returned {shown(item)} for {port.name}: expected a whole number 0..{limit - 1} "
                         f"({'a flag: true or false' if port.flag else port.describe()}) "
                         f"(inputs {describe_case(routine, case)})")
    return item


def reference_answers(routine: Routine, columns: list, cases: list[tuple] | None, memory: dict,
                      inside: np.ndarray | None = None, calls: list | None = None) -> tuple[list[np.ndarray], np.ndarray]:
    """The reference's answers for a block of cases, the one way the check gets them: one array per
    output (a table: (n, bytes)), and which cases it answered. The reference is called once on the
    arrays (`arrays = true`) or case by case; outside the domain (`inside` False) it may refuse a case
    or answer out of range; inside, that is a one-line error. `calls`: per case, the mocks' calls the
    reference takes by name (retro.routines.world); with arrays, a list per case."""
    n = len(columns[0])
    inside = np.ones(n, dtype=bool) if inside is None else inside
    if routine.reference_arrays:
        if calls is not None:
            memory = {**memory, **{name: [c[name] for c in calls] for name in calls[0]}} if calls else memory
        return _answers_on_arrays(routine, columns, memory, inside)
    return _answers_case_by_case(routine, cases if cases is not None else case_sets.columns_to_cases(columns),
                                 memory, inside, calls)


def _answers_case_by_case(routine: Routine, cases: list[tuple], memory: dict,
                          inside: np.ndarray, calls: list | None = None) -> tuple[list[np.ndarray], np.ndarray]:
    n = len(cases)
    answerable = np.ones(n, dtype=bool)
    answers = []
    blank = tuple(tuple(-1 for _ in p.places) if p.table else -1 for p in routine.outputs)
    for i, case in enumerate(cases):
        try:
            answers.append(expected_outputs(routine, case, memory, None if calls is None else calls[i]))
        except UserCodeError:  # a hang, an exit: never a refusal
            raise
        except InputError:
            if inside[i]:
                raise
            answers.append(blank)  # a reference may refuse inputs outside the domain: nothing to compare
            answerable[i] = False
    return [np.asarray([a[k] for a in answers], dtype=np.int64).reshape((n, len(port.places)) if port.table else (n,))
            for k, port in enumerate(routine.outputs)], answerable


def _answers_on_arrays(routine: Routine, columns: list, memory: dict,
                       inside: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    n = len(columns[0])
    where = f"{routine.spec_path}: reference {routine.reference_name} (arrays = true)"
    values = _call_on_arrays(routine, columns, memory, where)
    answerable = np.ones(n, dtype=bool)
    out, fitting = [], []  # per output, which answers fit it (None: flags, which fit every output)
    for port, item in zip(routine.outputs, values):
        array = _output_array(port, item, n, where)
        out.append(array)
        if _is_flags(item):  # 0 and 1 fit every output: no pass over the block
            fitting.append(None)
            continue
        fits = (array >= 0) & (array < (1 << port.bits))
        if port.table:
            fits = fits.all(axis=1)
        answerable &= fits
        fitting.append(fits)
    bad = np.flatnonzero(~answerable & inside) if any(fits is not None for fits in fitting) else ()
    if len(bad):
        i = int(bad[0])
        k = next(k for k, fits in enumerate(fitting) if fits is not None and not fits[i])
        port = routine.outputs[k]
        raise InputError(f"{where} returned {out[k][i].tolist()} for {port.name}: outside 0..{(1 << port.bits) - 1} "
                         f"(inputs {describe_case(routine, case_sets.case_of(columns, i))})")
    return out, answerable


def _call_on_arrays(routine: Routine, columns: list, memory: dict, where: str) -> list:
    """The reference called once on the block: its answer per output, in the outputs' order."""
    arguments = dict(zip(routine.input_names, columns))
    arguments.update({name: memory[name] for name in (*routine.reference_memory, *reference_calls(routine.world))
                      if name in memory})
    try:
        with np.errstate(all="ignore"):
            value = routine.reference(**arguments)
    except UserCodeError:
        raise
    except Exception as exc:  # the user's reference: whatever it raises is reported in one line
        raise InputError(f"{where} raised {type(exc).__name__}: {str(exc)[:200]}") from None
    if isinstance(value, dict):
        if set(value) != set(routine.output_names):
            raise InputError(f"{where} returned keys {sorted(value)} for the outputs {list(routine.output_names)}")
        return [value[name] for name in routine.output_names]
    if len(routine.outputs) == 1:
        return [value]
    values = list(value) if isinstance(value, (tuple, list)) else []
    if len(values) != len(routine.outputs):
        raise InputError(f"{where}: with {len(routine.outputs)} outputs it must return a dict or a tuple of "
                         f"{len(routine.outputs)} arrays")
    return values


def _is_flags(item) -> bool:
    return isinstance(item, np.ndarray) and item.dtype == bool


def _output_array(port, item, n: int, where: str) -> np.ndarray:
    """One output's answers as whole numbers of shape (n,) or (n, bytes) (a scalar stands for all)."""
    array = np.asarray(item)
    if array.dtype == bool:
        array = array.astype(np.int64)
    shape = (n, len(port.places)) if port.table else (n,)
    if array.shape != shape and array.ndim == 0:
        array = np.broadcast_to(array, shape)
    if array.shape != shape or (array.dtype != np.int64 and not np.issubdtype(array.dtype, np.integer)):
        raise InputError(f"{where} returned {array.dtype} of shape {array.shape} for {port.name}: expected "
                         f"whole numbers of shape {shape}")
    return array.astype(np.int64, copy=not array.flags.writeable)  # (a broadcast scalar becomes an array)
