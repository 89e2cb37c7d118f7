"""The compiled engine: a routine translated by `retro.cpu.translate` and compiled with numba, cached on
disk per routine and content, run on many calls at native speed (docs/compiled.md).

`compile_routine(...)` gives a `CompiledRoutine` (the function, how long it took, whether it came from
the cache); `CompiledRoutine.run(...)` runs a block of calls and returns per call the registers, P,
cycles, a status (returned, over the budget, or why it must run on the batched core instead) and the
bytes at the output addresses.

The cache: one folder per key under `$RETRO_CACHE/compiled` (default `~/.cache/retro/compiled`). The
key is a hash of the generated source, the translator's and helpers' code, and the versions of
Python, numba, llvmlite and numpy and the host CPU, so a routine whose bytes change, or another
machine's entry, never matches. An entry holds the generated module, numba's cache files beside it
and a manifest of their SHA-256 sums written after the compile; an entry whose manifest is missing,
unreadable, for another key, or whose files do not match it is deleted and built again (numba's index
is a pickle: nothing in an entry is loaded before its sums are checked). A lock file serialises
workers building the same entry.
"""

from __future__ import annotations

import fcntl
import hashlib
import importlib.util
import inspect
import json
import os
import platform
import shutil
import sys
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from retro.cpu import compiled_ops, translate
from retro.paths import CACHE_ENV, cache_dir
from retro.cpu.translate import FALLBACK, REGISTERS_OUT, RESULT_ROWS, SET_A, SET_FLAG, SET_P, SET_REGISTERS, SET_X, SET_Y, Translation, Untranslatable

MODULE_FILE = "routine.py"
MANIFEST_FILE = "manifest.json"
LOCK_FILE = ".lock"
FALLBACK_REASON = {translate.FALLBACK_STOP: "an instruction the compiled engine leaves to the batched core "
                                            "(BRK, RTI, JAM, an unstable opcode, STP or WAI)",
                   translate.FALLBACK_JUMP: "a jump to code not found before the run (RTS or JMP (ind) to an "
                                            "address no block starts at, or to one whose code is translated "
                                            "inside the block before it)",
                   translate.FALLBACK_WRITE: "a write into the routine's own code",
                   translate.FALLBACK_DECIMAL: "decimal mode on entry to code translated for binary mode only "
                                               "(no SED or PLP in it)"}


def signature(columns: int) -> str:
    """The compiled function's type: `columns` case columns come as a tuple of int64 arrays (at least
    one: numba types no index into an empty tuple; `run` passes zeros when there is none)."""
    cols = f"UniTuple(int64[::1], {max(columns, 1)})"
    return (f"void(int64[::1], int64[::1], int32[::1], uint8[::1], int32[::1], {cols}, int64[::1], uint8[:, ::1], "
            "int64[::1], int64, int64, int64, int64, int64[::1], int64[:, ::1], uint8[:, ::1])")


MEMORY = 0x10000


def numba_problem() -> str | None:
    """Why numba cannot be used here (None: it can)."""
    try:
        import numba  # noqa: F401
    except Exception as exc:  # an unsupported Python or numpy raises ImportError or worse at import
        return f"numba cannot be imported ({type(exc).__name__}: {exc})"
    return None


def cache_root() -> Path:
    return cache_dir("compiled")


@dataclass
class CompiledRoutine:
    translation: Translation
    function: object
    compile_seconds: float  # building (or loading) the function: numba's compile, or reading the cache
    from_cache: bool
    code_map: np.ndarray
    addr_block: np.ndarray
    _scratch: tuple | None = None  # (image bytes, the image as int64, memory as the calls leave it, the write log)

    def memory_for(self, image: bytes) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(image, working memory, log) for this image, kept between runs: every call restores what it
        wrote, so the working memory is the image again after a run (inputs put back by `run`)."""
        if self._scratch is None or self._scratch[0] != image:
            wide = np.frombuffer(image, dtype=np.uint8).astype(np.int64)
            self._scratch = (image, wide, wide.copy(), np.zeros(MEMORY, dtype=np.int32))
        return self._scratch[1:]

    def run(self, image: bytes, columns: tuple, base: np.ndarray, sp: int, budget: int, return_pc: int,
            return_sp: int, out_addr: np.ndarray, lane_addr: np.ndarray | None = None,
            lane_bytes: np.ndarray | None = None) -> dict:
        """Every call of the block (one per element of each column, `columns` the int64 arrays the
        routine was compiled to place: `compile_routine`) over `base` (A, X, Y, P), and `lane_bytes`
        one row per address of `lane_addr`. Its results as arrays by name (those the routine was
        compiled to write, `compile_routine`'s `results`, then RESULT_ROWS: cycles and status), the
        bytes at `out_addr` one row per address ("bytes")."""
        n = len(columns[0]) if columns else lane_bytes.shape[1]
        wide, mem, log = self.memory_for(image)
        columns = tuple(columns) or (np.zeros(n, dtype=np.int64),)
        if lane_addr is None:
            lane_addr, lane_bytes = np.zeros(0, dtype=np.int64), np.zeros((0, n), dtype=np.uint8)
        made_for = self.translation
        if ((made_for.lanes is not None and tuple(lane_addr.tolist()) != made_for.lanes)
                or (made_for.outputs is not None and tuple(out_addr.tolist()) != made_for.outputs)):
            raise ValueError("the lane or output addresses differ from those the routine was compiled for")
        names = [name for name, _ in made_for.results] + list(RESULT_ROWS)
        out = np.empty((len(names), n), dtype=np.int64)
        out_bytes = np.empty((len(out_addr), n), dtype=np.uint8)
        try:
            self.function(mem, wide, log, self.code_map, self.addr_block, columns, lane_addr, lane_bytes, base, sp,
                          budget, return_pc, return_sp, out_addr, out, out_bytes)
        finally:
            placed = list(self.translation.placed)
            mem[placed] = wide[placed]
            mem[lane_addr] = wide[lane_addr]
        results = dict(zip(names, out))
        results["bytes"] = out_bytes
        return results


def _versions() -> dict[str, str]:
    import llvmlite
    import llvmlite.binding
    import numba

    return {"python": sys.version, "numba": numba.__version__, "llvmlite": llvmlite.__version__,
            "numpy": np.__version__, "machine": platform.machine(), "cpu": llvmlite.binding.get_host_cpu_name(),
            "translator": str(translate.TRANSLATOR_VERSION)}


def _module_source(translation: Translation, columns: int) -> str:
    helpers = ", ".join(compiled_ops.HELPERS)
    return (f'"""Generated by retro.cpu.compiled: do not edit (the cache rebuilds it)."""\n'
            f"import numpy as np\nfrom numba import njit\nfrom retro.cpu.compiled_ops import {helpers}\n"
            f"{translation.source}\n{translation.function_name} = njit({signature(columns)!r}, cache=True, pipeline_class=Pipeline)"
            f"({translation.function_name})\n")


def cache_key(module: str) -> str:
    own = inspect.getsource(compiled_ops) + inspect.getsource(translate)
    text = json.dumps([module, hashlib.sha256(own.encode()).hexdigest(), _versions()], sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _entry_files(entry: Path) -> list[Path]:
    return sorted(p for p in entry.rglob("*") if p.is_file() and p.name not in (MANIFEST_FILE, LOCK_FILE)
                  and p.suffix != ".pyc")


def _valid(entry: Path, key: str, module: str) -> bool:
    """Whether the entry is whole and ours: the manifest for this key, every file's sum as written."""
    try:
        manifest = json.loads((entry / MANIFEST_FILE).read_text())
        if manifest.get("key") != key or (entry / MODULE_FILE).read_text() != module:
            return False
        files = {str(p.relative_to(entry)): _sha(p) for p in _entry_files(entry)}
        return files == manifest.get("files") and any(name.endswith(".nbc") for name in files)
    except (OSError, ValueError, UnicodeDecodeError, AttributeError):
        return False


def _write_manifest(entry: Path, key: str) -> None:
    files = {str(p.relative_to(entry)): _sha(p) for p in _entry_files(entry)}
    handle, temporary = tempfile.mkstemp(dir=entry, suffix=".tmp")
    with os.fdopen(handle, "w") as out:
        json.dump({"key": key, "files": files}, out)
    os.replace(temporary, entry / MANIFEST_FILE)


def _clear(entry: Path) -> None:
    for path in entry.iterdir():
        if path.name == LOCK_FILE:
            continue
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()


BLAS_PROBE = "scipy.linalg.cython_blas"


@contextmanager
def without_blas_probe():
    """numba's CPU target, on its first use in a process, asks whether a BLAS is there by importing
    scipy.linalg (0.4 s of the 0.55 s a cached routine took to load in a fresh process, measured);
    the generated code calls no BLAS, so while it loads that import fails at once (numba's
    np.correlate and np.convolve then keep their own loop; np.dot still finds scipy when typed later)."""
    if BLAS_PROBE in sys.modules or "numba.np.arraymath" in sys.modules:  # imported already, or probed
        yield
        return
    sys.modules[BLAS_PROBE] = None  # the import system's "not there": ImportError, parents untouched
    try:
        yield
    finally:
        if sys.modules.get(BLAS_PROBE, 0) is None:
            del sys.modules[BLAS_PROBE]


def _load(entry: Path, key: str, name: str):
    module_name = f"retro_compiled_{key[:24]}"
    spec = importlib.util.spec_from_file_location(module_name, entry / MODULE_FILE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module  # numba finds the module by name when it loads the cached code
    try:
        with without_blas_probe():
            spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[module_name]
        raise
    return getattr(module, name)


_LOADED: dict[str, tuple[object, float, bool]] = {}  # key -> (function, seconds, from the cache), this process


def _function(translation: Translation, columns: int) -> tuple[object, float, bool]:
    module = _module_source(translation, columns)
    key = cache_key(module)  # imports numba: not part of the compile time
    if key in _LOADED:
        return _LOADED[key]
    began = time.perf_counter()
    entry = cache_root() / key[:40]
    entry.mkdir(parents=True, exist_ok=True)
    with open(entry / LOCK_FILE, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        cached = _valid(entry, key, module)
        if not cached:
            _clear(entry)
            (entry / MODULE_FILE).write_text(module)
        try:
            function = _load(entry, key, translation.function_name)
        except Exception:
            if not cached:
                raise
            _clear(entry)  # the sums matched but numba refused what it wrote: build it again
            (entry / MODULE_FILE).write_text(module)
            function, cached = _load(entry, key, translation.function_name), False
        hits = sum(function.stats.cache_hits.values())
        if not cached or not hits:
            _write_manifest(entry, key)
        loaded = (function, time.perf_counter() - began, bool(cached and hits))
    _LOADED[key] = loaded
    return loaded


def compile_routine(image: bytes, entry: int, cpu: str, return_pc: int, inputs_at=(), columns: int = 0,
                    places: tuple = (), sets: tuple = (), lanes: tuple[int, ...] | None = None,
                    outputs: tuple[int, ...] | None = None, decimal_entry: bool = False,
                    results: tuple[tuple[str, str], ...] = REGISTERS_OUT) -> CompiledRoutine:
    """The routine at entry in this memory image, compiled (or loaded from the cache) for calls whose
    inputs come in `columns` case columns placed by `places` and `sets` rows (retro.cpu.translate's
    `_placing`; `CompiledRoutine.run`), and, when given, the `lane_addr` and `out_addr` every run
    passes (`lanes`, `outputs`: one line each in the code instead of a loop), and whether calls may
    start with D set (`decimal_entry`: ADC and SBC then keep decimal mode), and what its runs give
    per call (`results`: (name, expression) pairs, retro.cpu.translate's `_out_lines`; A, X, Y and
    P unless told); Untranslatable when the
    compiled engine does not take it (the message says why)."""
    problem = numba_problem()
    if problem is not None:
        raise Untranslatable(problem)
    translation = translate.translate(image.__getitem__, entry, cpu, return_pc, inputs_at, places, sets,
                                      None if lanes is None else tuple(lanes),
                                      None if outputs is None else tuple(outputs), decimal_entry, tuple(results))
    function, seconds, from_cache = _function(translation, columns)
    code_map = np.zeros(MEMORY, dtype=np.uint8)
    code_map[list(translation.code_bytes - translation.live_bytes)] = 1  # a write to a live operand is no fallback
    addr_block = np.full(MEMORY, translate.NO_BLOCK, dtype=np.int32)
    for address, number in translation.blocks.items():  # (a jump to an inlined block's number falls back:
        addr_block[address] = number  # the dispatch has no arm for it, translate's `else`)
    return CompiledRoutine(translation, function, seconds, from_cache, code_map, addr_block)


__all__ = ["CompiledRoutine", "FALLBACK", "FALLBACK_REASON", "RESULT_ROWS", "SET_A", "SET_FLAG", "SET_P", "SET_REGISTERS", "SET_X", "SET_Y",
           "Untranslatable", "cache_root", "compile_routine",
           "numba_problem"]
