"""Imported for its effect, by the server process the embedded Dask workers are forked from
(retro.workers, when the command has loaded compiled code): numba's CPU target made ready once there (its
implementation registries imported and installed, its runtime started), so each worker forked from
it inherits that instead of doing it again when it loads its first compiled routine.

That first load costs about 0.5 CPU-second in a process where numba is only imported (most of it
importing numba's array, linear-algebra and typed-container implementations, which `refresh` does
before it installs them), measured in benchmarks/dask_cpu.py; once made ready here, about 0.1. Never
imported by retro itself: a process that compiles nothing does not pay for it. Any failure is left
to the worker's own load, which then reports it as usual (the server must not stop on it).
"""

from __future__ import annotations


def make_ready() -> bool:
    """numba's CPU target refreshed; False when numba cannot be used here (the worker finds out itself)."""
    try:
        from numba.core.registry import cpu_target

        from retro.cpu.compiled import without_blas_probe

        with without_blas_probe():  # as a worker's own first load would (retro.cpu.compiled)
            cpu_target.target_context.refresh()
    except Exception:  # numba missing, or a version without this path: the worker loads as before
        return False
    return True


READY = make_ready()
