"""The cases a check runs, made lazily in chunks (memory stays bounded whatever the counts).

Parts, in order:
- boundary: the spec's `boundary` function (hand-picked edges), always;
- exhaustive: every combination of the values of the inputs named in `exhaustive` (the other inputs
  drawn at random per case). Without --exhaustive, all of it when it has at most BOUNDED_PRODUCT
  cases, else a seeded random sample of BOUNDED_SAMPLE of them;
- sweep: the spec's `sweep` function (structured exhaustive slices), with --exhaustive only: grids
  (retro.routines.grid: counted, entered at any case) or the cases it yields;
- random: `random` cases over every input (the spec's `random_generator`, or uniform over each
  input's values), at most RANDOM_BOUNDED without --exhaustive.
A case is a tuple in the inputs' order: an int per number or flag, a tuple of bytes per table.
Cases from a user's function may also be dicts by input name; each is checked against its inputs'
widths (one-line error naming the function and the case).
"""

from __future__ import annotations

import ast
from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator
from dataclasses import dataclass, replace
from itertools import chain, islice

import numpy as np

from retro.errors import InputError
from retro.routines.grid import GRID_BLOCK, Grid, one_row
from retro.routines.sandbox import guarded, shown
from retro.routines.places import Values
from retro.routines.spec import Port, Routine, call_with
from retro.routines.where import input_ranges

RANDOM_BOUNDED = 2_000  # random cases without --exhaustive
BOUNDED_PRODUCT = 1 << 16  # an exhaustive set this small runs in full even without --exhaustive
BOUNDED_SAMPLE = 4_096  # cases sampled from a larger exhaustive set without --exhaustive
CHUNK = 4_000
BLOCK_BYTES = 8 << 20  # a column block for the batched core: 8 MiB (65,536 cases of 16 numbers; fewer of tables)
SEEK_BLOCK = 1 << 16  # random draws are made per block of this many cases, each block from its own generator
# (`_block_rng`): a worker enters a part at any block without drawing the ones before it
EXHAUSTIVE_RNG_OFFSET = 2  # the non-swept inputs of the exhaustive part draw from seed + 2
PROBE_RNG_OFFSET = 4  # the probe of the domain's share draws from seed + 4 (entry state: seed + 3)
INSIDE_SHARE = 1 / 20  # random cases are drawn inside the domain when fewer uniform draws than this land there
PROBE = 4_096  # uniform draws that estimate the domain's share
ENUMERATE_LIMIT = 1 << 22  # a box of at most this many combinations is enumerated, its valid ones kept
DRAW_BUDGET = 256  # candidates drawn in the box per random case wanted, at most (then fewer cases) ...
DRAW_FLOOR, DRAW_CEILING = 1 << 22, 1 << 25  # ... but at least 4 Mi and at most 32 Mi of them
DRAW_BATCH = 1 << 16  # candidates drawn (and tested against the domain) at once
EAGER_INSIDE = 1 << 20  # up to this many random cases inside the domain are drawn when the plan is made
GRID_VALUES = 1 << 20  # an exhaustive product is made as a grid when each swept input has at most this many values


Columns = list  # one numpy array per input, in input order: (n,) int64, or (n, size) for a table


@dataclass(frozen=True)
class Part:
    name: str  # "boundary", "exhaustive", "sweep", "random"
    count: int | None  # None when a sweep function does not say
    total: int  # cases of the full space this part stands for (exhaustive: the whole product)
    blocks: Callable[[], Iterator[Columns]]  # a fresh iterator of column blocks of at most CHUNK cases
    draw: "DomainDraw | None" = None  # the random part: how its cases were drawn (with a `where` domain)
    inside: int | None = None  # the exhaustive part: its combinations inside the domain, when only those run
    seek: Callable[[int], Iterator[Columns]] | None = None  # its blocks from a case index on, without making the
    # cases before it (None: they are made and dropped; `stream`)
    from_start: bool = False  # its seek runs the part's function from its start (the cases before are counted,
    # not checked nor converted): reached at a cost that grows with the index
    aligned: Callable[[int, int, int], Iterator[Columns]] | None = None  # aligned(start, phase, size): as
    # seek(start), its blocks cut where (case - phase) % size == 0, so that a stream's blocks are made whole,
    # not joined from pieces (None: its own cuts)

    @property
    def cases(self) -> Iterator[tuple]:
        """The part's cases one by one (for the scalar engine), in the same order as its blocks."""
        for block in self.blocks():
            for start in range(0, len(block[0]), CHUNK):  # a CHUNK of tuples at a time, not a whole block
                yield from columns_to_cases([column[start:start + CHUNK] for column in block])


    def head(self, n: int) -> Columns | None:
        """The part's first n cases (fewer when it has fewer) as one column block of int64 arrays, as
        `cases_to_columns` makes them; None for a part without cases. Only the blocks that hold them
        are made, and only those n cases are kept."""
        pieces: list[Columns] = []
        have = 0
        for block in self.blocks():
            take = min(n - have, len(block[0]))
            if take:
                pieces.append([column[:take] for column in block])
                have += take
            if have >= n:
                break  # (before the next block is made)
        if not have:
            return None
        return [np.concatenate([piece[k] for piece in pieces]).astype(np.int64, copy=False) if len(pieces) > 1
                else np.asarray(pieces[0][k], dtype=np.int64) for k in range(len(pieces[0]))]


def columns_to_cases(block: Columns) -> list[tuple]:
    return list(zip(*(c.tolist() if c.ndim == 1 else [tuple(row) for row in c.tolist()] for c in block)))


def case_of(block: Columns, i: int) -> tuple:
    """Case i of a column block, as a tuple."""
    return columns_to_cases([c[i:i + 1] for c in block])[0]


def cases_to_columns(routine: Routine, cases: list[tuple]) -> Columns:
    columns = []
    for index, port in enumerate(routine.inputs):
        column = np.asarray([case[index] for case in cases], dtype=np.int64)
        columns.append(column.reshape(len(cases), len(port.places)) if port.table else column)
    return columns


def random_count(routine: Routine, exhaustive: bool, override: int | None) -> int:
    if override is not None:
        return override
    return routine.random if exhaustive else min(routine.random, RANDOM_BOUNDED)


def plan(routine: Routine, *, exhaustive: bool, seed: int | None = None, random: int | None = None,
         bounded_product: int = BOUNDED_PRODUCT) -> list[Part]:
    """The parts of a check, each with its case count and a lazy iterable of cases. Without
    `exhaustive`, an exhaustive set larger than `bounded_product` is sampled."""
    seed = routine.seed if seed is None else seed
    parts = []
    if routine.boundary is not None:
        made = list(_function_blocks(routine, "cases.boundary",
                                     call_with(routine.boundary, {"seed": seed, "rng": np.random.default_rng(seed)})))
        count = sum(len(block[0]) for block in made)
        parts.append(Part("boundary", count, count, lambda: iter(made)))
    if routine.exhaustive:
        total = routine.exhaustive_count()
        valid = _valid_sweep(routine, total)
        if valid is not None:  # only the combinations inside the domain (a small share of them)
            full = exhaustive or len(valid) <= bounded_product
            sample = None if full else min(BOUNDED_SAMPLE, bounded_product)
            parts.append(Part("exhaustive", len(valid) if full else sample, total,
                              lambda: _product(routine, seed, sample, valid), inside=len(valid),
                              seek=(lambda start: _product(routine, seed, None, valid, start)) if full else None))
        elif exhaustive or total <= bounded_product:
            parts.append(Part("exhaustive", total, total, lambda: _product(routine, seed, None),
                              seek=lambda start: _product(routine, seed, None, start=start)))
        else:
            sample = min(BOUNDED_SAMPLE, bounded_product)
            parts.append(Part("exhaustive", sample, total, lambda: _product(routine, seed, sample)))
    if exhaustive and routine.sweep is not None:
        parts.append(_sweep_part(routine, seed))
    count = random_count(routine, exhaustive, random)
    if count:
        draw = domain_draw(routine, seed, count)
        if draw is not None and draw.inside:
            parts.append(Part("random", draw.drawn, count, draw.blocks, draw, seek=draw.seek))
        else:
            parts.append(Part("random", count, count, lambda: _random(routine, seed, count), draw,
                              seek=lambda start: _random(routine, seed, count, start)))
    return parts


def chunks(cases: Iterable[tuple], size: int = CHUNK) -> Iterator[list[tuple]]:
    iterator = iter(cases)
    while True:
        chunk = list(islice(iterator, size))
        if not chunk:
            return
        yield chunk


def batches(parts: list[Part], size: int) -> Iterator[Columns]:
    """The parts' cases as column blocks of `size` cases (the last one shorter), in case order; fewer
    when a case holds many values (table inputs), so that a block stays within BLOCK_BYTES. The parts'
    blocks are let go as soon as they are used up; a block's columns are read, never written (a grid's
    may be shared with other blocks)."""
    blocks = chain.from_iterable(part.blocks() for part in parts)
    first = next(blocks, None)
    if first is not None:
        yield from rechunked(chain([first], blocks), block_size(first, size))


def stream(parts: list[Part], size: int, first: int = 0,
           counted: Callable[[int, int], None] | None = None) -> Iterator[Columns]:
    """The parts' cases from case `first` on (counted over all the parts), in blocks of `size` cases
    (the last one shorter): what a worker makes of a task's description. A part wholly before `first`
    is passed over by its count, one it starts in is entered by its `seek` when it has one (a spec's sweep
    function's runs from its start, counting the cases before `first`); else its cases before `first`
    are made and dropped. `counted(i, n)`: told the count of part i, one that did not say it, once made."""
    return rechunked(_cases_from(parts, first, counted, size), size)


def reachable(parts: list[Part], first: int) -> bool:
    """Whether `stream` reaches case `first` without making (or, with a sweep function, counting) the
    cases before it."""
    done = 0
    for part in parts:
        if part.count is not None and done + part.count <= first:
            done += part.count
            continue
        return first == done or (part.seek is not None and not part.from_start)
    return True


def _cases_from(parts: list[Part], first: int, counted: Callable[[int, int], None] | None,
                size: int | None = None) -> Iterator[Columns]:
    """The parts' blocks from case `first`; a part that can cuts its blocks at the multiples of `size`
    counted over all the parts (where a stream from any such multiple cuts its own)."""
    done = 0  # cases of the parts before this one
    for index, part in enumerate(parts):
        before = done
        if part.count is not None and done + part.count <= first:
            done += part.count
            continue
        skip = max(0, first - done)
        if part.aligned is not None and size is not None:
            yield from part.aligned(skip, -done % size, size)
            done += part.count
        elif skip and part.seek is not None:
            if part.from_start:  # (its seek returns how many cases the part made in all)
                done += yield from part.seek(skip)
            else:
                yield from part.seek(skip)
                done += part.count
        else:
            seen = 0  # the part's cases passed over
            for block in part.blocks():
                n = len(block[0])
                if seen + n > skip:
                    yield block if seen >= skip else [column[skip - seen:] for column in block]
                seen += n
            done += seen
        if part.count is None and counted is not None:
            counted(index, done - before)


def rechunked(blocks: Iterable[Columns], size: int) -> Iterator[Columns]:
    """Column blocks cut and joined into blocks of `size` cases (the last one shorter): a block of `size`
    cases whose columns are contiguous (or one table row repeated: grid.one_row) passed on as it is, the
    others copied."""
    pending: deque[Columns] = deque()
    offset = count = 0  # where the first pending block's unused cases start; cases pending in all
    for block in blocks:
        pending.append(block)
        count += len(block[0])
        while count >= size:
            taken, offset = _take(pending, offset, size)
            count -= size
            yield taken
    if count:
        yield _take(pending, offset, count)[0]


def _take(pending: deque, offset: int, size: int) -> tuple[Columns, int]:
    """`size` cases from the front of `pending` (the first block from `offset`; a whole contiguous block as it
    is, else copied); the new offset."""
    block = pending[0]
    if not offset and len(block[0]) == size and all(column.flags.c_contiguous or one_row(column) is not None
                                                    for column in block):  # passed on (one row repeated too)
        pending.popleft()
        return block, 0
    pieces = []
    while size:
        block = pending[0]
        available = len(block[0]) - offset
        used = min(available, size)
        pieces.append([column[offset:offset + used] for column in block])
        size -= used
        if used == available:
            pending.popleft()
            offset = 0
        else:
            offset += used
    return [np.concatenate(columns) for columns in zip(*pieces)], offset


def block_size(block: Columns, size: int) -> int:
    """At most `size` cases, and at most BLOCK_BYTES of columns: a block travels to a worker process
    (pickled: twice its size), several are in flight, and the worker holds it beside its lanes."""
    per_case = sum(column.itemsize * (column.shape[1] if column.ndim == 2 else 1) for column in block)
    return max(CHUNK, min(size, BLOCK_BYTES // max(per_case, 1)))


# ---- exhaustive product ----------------------------------------------------------------------------

def _block_rng(seed: int, block: int) -> np.random.Generator:
    """The generator of the random draws of a part's block `block` (of SEEK_BLOCK cases): the first
    block's is the part's seeded generator, as before blocks existed (a part of at most SEEK_BLOCK
    cases draws the cases it always drew); block k's is that generator jumped k times (numpy's
    PCG64.jumped: streams apart by about 2^127 draws, made for parallel streams), so any block is
    drawn without drawing the blocks before it, and the cases do not depend on how a run is split."""
    rng = np.random.default_rng(seed)
    return rng if block == 0 else np.random.Generator(rng.bit_generator.jumped(block))


def _by_block(count: int, start: int, block_of: Callable[[int, int, int], Iterator[Columns]]) -> Iterator[Columns]:
    """Cases start..count-1 of a part made per SEEK_BLOCK: `block_of(k, lo, hi)` yields the column blocks
    of cases lo..hi-1 of block k (the first block entered is cut at `start`)."""
    first = start // SEEK_BLOCK
    blocks = (block_of(k, k * SEEK_BLOCK, min(count, (k + 1) * SEEK_BLOCK)) for k in range(first, -(-count // SEEK_BLOCK)))
    return _skipped(chain.from_iterable(blocks), start - first * SEEK_BLOCK)


def _skipped(blocks: Iterable[Columns], skip: int) -> Iterator[Columns]:
    """The column blocks without their first `skip` cases."""
    seen = 0
    for columns in blocks:
        n = len(columns[0])
        if seen + n > skip:
            yield columns if seen >= skip else [column[skip - seen:] for column in columns]
        seen += n


def _product(routine: Routine, seed: int, sample: int | None, valid: np.ndarray | None = None,
             start: int = 0) -> Iterator[Columns]:
    """Every combination (mixed-radix counting over the swept inputs' values), in blocks (from
    combination `start`); or a seeded sample of `sample` distinct combinations; `valid`: only these
    combinations (their indices). The inputs not swept are drawn per case, per SEEK_BLOCK (`_block_rng`)
    unless sampled."""
    ports = routine.part_inputs("exhaustive")
    swept = [i for i, port in enumerate(ports) if port.name in routine.exhaustive]
    radices = [ports[i].count for i in swept]
    total = int(np.prod(radices, dtype=object))

    def digit_columns(indices: np.ndarray) -> list:
        columns: list = [None] * len(ports)
        rest = indices.copy()
        for i, radix in zip(reversed(swept), reversed(radices)):  # the last swept input varies fastest
            digit = rest % np.uint64(radix)
            rest //= np.uint64(radix)
            columns[i] = _digit_values(ports[i], digit)
        return columns

    def drawn(columns: list, rng: np.random.Generator, n: int) -> Columns:
        """The inputs not swept drawn into `columns`: per CHUNK of cases, input by input (the draws'
        order since blocks were made a CHUNK at a time)."""
        if len(swept) == len(ports):
            return columns
        out = [column if column is not None else
               np.empty((n, len(port.places)) if port.table else n, dtype=np.int64)
               for column, port in zip(columns, ports)]
        for at in range(0, n, CHUNK):
            m = min(CHUNK, n - at)
            for i, port in enumerate(ports):
                if columns[i] is None:
                    out[i][at:at + m] = _random_column(port, rng, m)
        return out

    if sample is not None:
        rng = np.random.default_rng(seed + EXHAUSTIVE_RNG_OFFSET)
        if valid is not None:
            picked = valid[np.sort(rng.choice(len(valid), size=sample, replace=False))]
        else:
            picked = np.sort(rng.choice(total, size=sample, replace=False).astype(np.uint64))
        for i in range(0, sample, CHUNK):
            indices = picked[i:i + CHUNK]
            yield drawn(digit_columns(indices), rng, len(indices))
        return
    # every combination in order: the swept inputs' columns from a grid of their values (runs and periods,
    # not a division per case), unless a table is swept or an input has very many values
    grid = None if any(ports[i].table or ports[i].count > GRID_VALUES for i in swept) else Grid(
        {f"input{i}": _digit_values(ports[i], np.arange(ports[i].count, dtype=np.uint64)) for i in swept})

    def block_of(block: int, lo: int, hi: int) -> Iterator[Columns]:
        rng = _block_rng(seed + EXHAUSTIVE_RNG_OFFSET, block)
        if valid is None and grid is not None:
            columns: list = [None] * len(ports)
            for i, (_, column) in zip(swept, grid._axis_columns(lo, hi)):
                columns[i] = column.array
        else:
            positions = np.arange(lo, hi, dtype=np.uint64)
            columns = digit_columns(positions if valid is None else valid[positions.astype(np.int64)])
        yield drawn(columns, rng, hi - lo)
    yield from _by_block(total if valid is None else len(valid), start, block_of)


def _valid_sweep(routine: Routine, total: int) -> np.ndarray | None:
    """The indices of the exhaustive part's combinations that meet the domain's conditions on the swept
    inputs alone, when those keep fewer than INSIDE_SHARE of at most ENUMERATE_LIMIT combinations
    (running only them is then cheaper than running every one); else None: every combination runs."""
    swept = set(routine.exhaustive)
    own = [c for c in routine.domain if c.term is not None and
           {n.id for n in ast.walk(c.term) if isinstance(n, ast.Name)} & set(routine.input_names) <= swept]
    if not own or total > ENUMERATE_LIMIT:
        return None
    ports = routine.part_inputs("exhaustive")
    indices = [i for i, port in enumerate(ports) if port.name in swept]
    valid = []
    for start in range(0, total, 1 << 16):
        block = np.arange(start, min(start + (1 << 16), total), dtype=np.uint64)
        digits = _combinations([ports[i] for i in indices], block)
        columns = [np.zeros((len(block), len(p.places)) if p.table else len(block), dtype=np.int64) for p in ports]
        for i, column in zip(indices, digits):
            columns[i] = column
        inside = np.ones(len(block), dtype=bool)
        for condition in own:
            inside &= condition.over(columns)
        valid.append(block[inside])
    kept = np.concatenate(valid)
    return kept if 0 < len(kept) < INSIDE_SHARE * total else None


def _digit_values(port: Port, digit: np.ndarray) -> np.ndarray:
    values = port.values
    if not port.table:
        if values.listed is None:
            return digit.astype(np.int64) + values.lo
        return np.asarray(values.listed, dtype=np.int64)[digit.astype(np.int64)]
    size = len(port.places)
    out = np.empty((len(digit), size), dtype=np.int64)
    rest = digit.copy()
    for byte in range(size):  # the first byte varies fastest
        out[:, byte] = rest % np.uint64(values.count)
        rest //= np.uint64(values.count)
    return out + values.lo if values.listed is None else np.asarray(values.listed, dtype=np.int64)[out]


def _random_column(port: Port, rng: np.random.Generator, n: int) -> np.ndarray:
    values = port.values
    shape = (n, len(port.places)) if port.table else (n,)
    if values.listed is not None:
        return np.asarray(values.listed, dtype=np.int64)[rng.integers(0, len(values.listed), size=shape)]
    return rng.integers(values.lo, values.hi + 1, size=shape, dtype=np.int64)


# ---- random ------------------------------------------------------------------------------------------

def _random(routine: Routine, seed: int, count: int, start: int = 0) -> Iterator[Columns]:
    """The random part from case `start` on: per SEEK_BLOCK cases, from that block's generator
    (`_block_rng`), the spec's random_generator called once per block, or uniform draws per CHUNK."""
    ports = routine.part_inputs("random")

    def block_of(block: int, lo: int, hi: int) -> Iterator[Columns]:
        rng, n = _block_rng(seed, block), hi - lo
        if routine.random_generator is not None:
            made = call_with(routine.random_generator, {"rng": rng, "count": n, "n": n, "seed": seed})
            yield from _function_blocks(routine, "cases.random_generator", made, expected=n)
            return
        for at in range(0, n, CHUNK):
            m = min(CHUNK, n - at)
            yield [_random_column(port, rng, m) for port in ports]
    return _by_block(count, start, block_of)


# ---- random cases inside the domain -------------------------------------------------------------------

@dataclass(frozen=True)
class DomainDraw:
    """How the random part meets a `where` domain: the share of uniform draws that land inside it
    (estimated from PROBE of them), and, when that share is small (or the spec asks), the cases drawn
    inside it instead: from the combinations of a box narrowed by the domain's comparisons, all
    enumerated when few, else drawn in the box and kept when inside (at most DRAW_BUDGET candidates
    per case wanted, within DRAW_FLOOR..DRAW_CEILING: fewer cases when the domain is too rare even
    there)."""

    inside: bool  # the random cases were drawn inside the domain
    share: float  # of uniform draws over the inputs' values, those inside the domain (estimated)
    requested: int
    drawn: int  # random cases made (requested, unless the budget ran out)
    method: str | None = None  # "enumerated" or "rejection" (drawn in the box, kept when inside)
    ranges: tuple[tuple[str, int, int], ...] = ()  # the box: each number input's narrowed range
    candidates: int = 0  # combinations enumerated, or candidates drawn in the box
    made: tuple = ()  # the column blocks (drawn when the plan is made)
    lazy: Callable[[], Iterator[Columns]] | None = None  # a generator of them, for very many cases

    def blocks(self) -> Iterator[Columns]:
        return self.lazy() if self.lazy is not None else iter(self.made)

    @property
    def seek(self) -> Callable[[int], Iterator[Columns]] | None:
        """The cases from an index on: the drawn blocks passed over, the enumerated ones picked per
        SEEK_BLOCK; None for very many cases drawn lazily by rejection (made from the first)."""
        if self.method == "enumerated":
            return self.lazy
        return None if self.lazy is not None else lambda start: _skipped(self.made, start)


def domain_draw(routine: Routine, seed: int, count: int) -> DomainDraw | None:
    """The random part's draw against the domain (None: no domain, or the spec's own generator)."""
    if not routine.domain or routine.random_generator is not None or not count:
        return None
    ports = routine.part_inputs("random")
    probing = np.random.default_rng(seed + PROBE_RNG_OFFSET)
    probe = [_random_column(port, probing, PROBE) for port in ports]
    share = float(in_domain(routine, probe).mean())
    if not (routine.random_inside or (routine.random_inside is None and share < INSIDE_SHARE)):
        return DomainDraw(False, share, count, count)
    box = _narrowed(routine, ports)
    empty = next((p.name for p in box if p.values is None), None)
    if empty is not None:
        raise InputError(f"{routine.spec_path}: cases.where: no value of {empty} within its values lies inside the "
                         f"domain: nothing can be checked")
    ranges = tuple((p.name, p.values.lo, p.values.hi) for p in box if not p.table)
    total = 1
    for port in box:
        total *= port.count
    if total <= ENUMERATE_LIMIT:
        valid = _valid_combinations(routine, box, total)
        if not len(valid):
            raise InputError(f"{routine.spec_path}: cases.where: none of the {total:,} combinations of the inputs' "
                             f"values lies inside the domain: nothing can be checked")

        def enumerated(start: int = 0) -> Iterator[Columns]:  # a fresh generator each time: the same cases
            def block_of(block: int, lo: int, hi: int) -> Iterator[Columns]:
                picks = _block_rng(seed, block)
                for at in range(lo, hi, CHUNK):
                    yield _combinations(box, valid[picks.integers(0, len(valid), size=min(CHUNK, hi - at))])
            return _by_block(count, start, block_of)
        return DomainDraw(True, share, count, count, "enumerated", ranges, total, lazy=enumerated)
    if count > EAGER_INSIDE:
        return DomainDraw(True, share, count, count, "rejection", ranges, 0,
                          lazy=lambda: _draw_inside(routine, box, seed, count, strict=True)[0])
    blocks, candidates = _draw_inside(routine, box, seed, count, strict=False)
    made = tuple(blocks)
    if not made:
        raise InputError(f"{routine.spec_path}: cases.where: none of {candidates():,} random draws lies inside the "
                         f"domain: nothing can be checked (narrow the inputs' values, or give cases: boundary)")
    return DomainDraw(True, share, count, sum(len(b[0]) for b in made), "rejection", ranges, candidates(), made)


def in_domain(routine: Routine, columns: Columns) -> np.ndarray:
    """Per case: whether it lies inside the spec's domain (every `where` condition holds)."""
    inside = np.ones(len(columns[0]), dtype=bool)
    for condition in routine.domain:
        inside &= condition.over(columns)
    return inside


def _narrowed(routine: Routine, ports: tuple[Port, ...]) -> list[Port]:
    """The ports with their values narrowed to the ranges the domain's comparisons allow (a port whose
    range is empty gets values None)."""
    ranges = input_ranges(routine.domain, {p.name: (p.values.lo, p.values.hi) for p in ports if not p.table})
    out = []
    for port in ports:
        if port.table or ranges[port.name] == (port.values.lo, port.values.hi):
            out.append(port)
            continue
        lo, hi = ranges[port.name]
        if port.values.listed is not None:
            kept = tuple(v for v in port.values.listed if lo <= v <= hi)
            values = Values(min(kept), max(kept), kept) if kept else None
        else:
            values = Values(lo, hi) if lo <= hi else None
        out.append(replace(port, values=values))
    return out


def _combinations(box: list[Port], indices: np.ndarray) -> Columns:
    """The combinations at mixed-radix `indices` of the box (the last input varies fastest)."""
    rest = indices.astype(np.uint64)
    columns: list = [None] * len(box)
    for i in reversed(range(len(box))):
        radix = np.uint64(box[i].count)
        columns[i] = _digit_values(box[i], rest % radix)
        rest = rest // radix
    return columns


def _valid_combinations(routine: Routine, box: list[Port], total: int) -> np.ndarray:
    """The indices of the box's combinations inside the domain."""
    valid = []
    for start in range(0, total, 1 << 16):
        indices = np.arange(start, min(start + (1 << 16), total), dtype=np.uint64)
        valid.append(indices[in_domain(routine, _combinations(box, indices))])
    return np.concatenate(valid)


def _draw_inside(routine: Routine, box: list[Port], seed: int, count: int, strict: bool):
    """Blocks of cases drawn uniformly in the box and kept when inside the domain, and a function
    giving the candidates drawn so far; at most DRAW_BUDGET candidates per case wanted (`strict`:
    running out is an error, for a part whose count was promised)."""
    rng = np.random.default_rng(seed)
    drawn = [0]

    def blocks() -> Iterator[Columns]:
        made = 0
        budget = min(max(DRAW_BUDGET * count, DRAW_FLOOR), DRAW_CEILING)
        while made < count and drawn[0] < budget:
            candidates = [_random_column(port, rng, DRAW_BATCH) for port in box]
            drawn[0] += DRAW_BATCH
            kept = [c[in_domain(routine, candidates)] for c in candidates]
            kept = [c[:count - made] for c in kept]
            made += len(kept[0])
            for start in range(0, len(kept[0]), CHUNK):
                yield [c[start:start + CHUNK] for c in kept]
        if strict and made < count:
            raise InputError(f"{routine.spec_path}: cases.where: {drawn[0]:,} random draws gave only {made:,} cases "
                             f"inside the domain of the {count:,} asked for: narrow the inputs' values")
    return blocks(), lambda: drawn[0]


def _sweep_part(routine: Routine, seed: int) -> Part:
    """The spec's sweep: grids (retro.routines.grid) have a count and are entered at any case; cases a
    function yields have neither (`_lazy_sweep`)."""
    made = [call_with(routine.sweep, {"seed": seed, "rng": np.random.default_rng(seed)})]
    grids = _grids(routine, made[0])
    if grids is None:
        def fresh():  # the first use takes what the plan made (a list is not made twice)
            return made.pop() if made else call_with(routine.sweep, {"seed": seed, "rng": np.random.default_rng(seed)})
        return Part("sweep", None, 0, lambda: _lazy_sweep(routine, fresh()),
                    seek=lambda start: _lazy_sweep(routine, fresh(), start), from_start=True)
    count = sum(grid.count for grid in grids)
    return Part("sweep", count, count, lambda: _grid_blocks(routine, grids),
                seek=lambda start: _grid_blocks(routine, grids, start),
                aligned=lambda start, phase, size: _grid_blocks(routine, grids, start, (phase, size)))


def _grids(routine: Routine, made) -> list[Grid] | None:
    """The grids a sweep function returned (a Grid, or a list or tuple of them), else None."""
    if isinstance(made, Grid):
        return [made]
    if isinstance(made, (list, tuple)) and made and any(isinstance(g, Grid) for g in made):
        wrong = next((g for g in made if not isinstance(g, Grid)), None)
        if wrong is not None:
            raise InputError(f"{routine.spec_path}: cases.sweep: a list of Grids holds {_short(wrong)}: return "
                             f"either Grids or cases (column blocks), not both")
        return list(made)
    return None


def _grid_blocks(routine: Routine, grids: list[Grid], start: int = 0,
                 cuts: tuple[int, int] | None = None) -> Iterator[Columns]:
    """The grids' cases from case `start` on (counted over all of them), as checked column blocks: the
    combinations before it are never made. Blocks are cut at each grid's multiples of GRID_BLOCK, or with
    `cuts` (phase, size) where (case - phase) % size == 0, the cases counted over all the grids (and at
    each grid's end)."""
    where = f"{routine.spec_path}: cases.sweep"
    before = 0  # the cases of the grids before this one
    for number, grid in enumerate(grids, 1):
        offset, before = before, before + grid.count
        if start >= grid.count:
            start -= grid.count
            continue
        make = None if grid.make is None else guarded(grid.make, f"{where} (Grid {number}'s make)", faults_only=False)
        phase, size = (0, GRID_BLOCK) if cuts is None else ((cuts[0] - offset) % cuts[1], cuts[1])
        lo = start
        start = 0
        while lo < grid.count:
            hi = min(grid.count, lo + size - (lo - phase) % size)
            try:
                block, known = grid.made_block(lo, hi, make)
            except ValueError as exc:
                raise InputError(f"{where}: {exc}") from None
            yield _block_columns(routine, block, f"{where} (Grid {number}, cases {lo:,}..{hi - 1:,})", known)
            lo = hi


def _lazy_sweep(routine: Routine, made, start: int = 0) -> Generator[Columns, None, int]:
    """The cases a spec's sweep function made (`made`: what it returned) from case `start` on: it runs from
    its start (a function can only be run from there); the cases before `start` are counted, not checked
    nor converted. Returns how many cases it made in all."""
    return (yield from _function_blocks(routine, "cases.sweep", made, skip=start))


# ---- cases from users' functions ----------------------------------------------------------------------

def _function_blocks(routine: Routine, key: str, made, expected: int | None = None,
                     skip: int = 0) -> Generator[Columns, None, int]:
    """Cases from a spec's function as column blocks. The function returns (or yields) cases one by
    one (tuples in input order, or dicts by name), or column blocks: dicts of numpy arrays by input
    name, one element per case (a table input: one row of bytes per case) - the fast form. The first
    `skip` cases are passed over: counted, not checked (the run that makes them checks them)."""
    where = f"{routine.spec_path}: {key}"
    if isinstance(made, dict):
        made = [made]
    try:
        iterator = iter(made)
    except TypeError:
        raise InputError(f"{where}: the function must return a list or iterable of cases or of column "
                         f"blocks, got {type(made).__name__}") from None
    first = next(iterator, None)
    if first is None:
        produced = 0
    elif isinstance(first, dict) and any(isinstance(v, np.ndarray) for v in first.values()):
        produced = 0
        for block in chain([first], iterator):
            if skip and isinstance(block, dict) and block:
                n = len(next(iter(block.values())))
                if produced + n <= skip:  # wholly before the first case wanted
                    produced += n
                    continue
            columns = _block_columns(routine, block, where)
            if produced < skip:
                columns = [column[skip - produced:] for column in columns]
                produced = skip
            produced += len(columns[0])
            if len(columns[0]):
                yield columns
    else:
        produced = sum(1 for _ in islice(iterator, skip - 1)) + 1 if skip else 0  # (`first` is one of them)
        rest = chain([first], iterator) if not skip else iterator
        for chunk in chunks(_checked(routine, key, rest)):
            produced += len(chunk)
            yield cases_to_columns(routine, chunk)
    if expected is not None and produced != expected:
        raise InputError(f"{where}: asked for {expected} cases, the function returned {produced}")
    return produced


def _block_columns(routine: Routine, block, where: str, known: dict[str, tuple[int, int]] | None = None) -> Columns:
    """One column block (a dict of arrays by input name), checked: every input, one length, widths (`known`:
    the least and greatest value of the columns whose values the caller knows, by name: a grid's)."""
    if not isinstance(block, dict):
        raise InputError(f"{where}: after a column block (a dict of arrays) every item must be one, got "
                         f"{type(block).__name__}")
    wrong = _wrong_names(block, routine.input_names)
    if wrong:
        raise InputError(f"{where}: a column block {wrong}")
    columns: Columns = []
    for port in routine.inputs:
        column = _port_column(port, block[port.name], where)
        if columns and len(column) != len(columns[0]):
            raise InputError(f"{where}: column {port.name} has {len(column)} cases, {routine.inputs[0].name} "
                             f"{len(columns[0])}")
        _check_column_fits(port, column, where, None if known is None else known.get(port.name))
        columns.append(column if column.dtype == np.int64 else column.astype(np.int64))
    return columns


def _wrong_names(given, names: tuple[str, ...]) -> str:
    """What is wrong with the input names of a case or block by name ("" when nothing)."""
    missing = [n for n in names if n not in given]
    if missing:
        return f"lacks {missing[0]!r}"
    extra = [k for k in given if k not in names]
    return f"has unknown input {extra[0]!r}" if extra else ""


def _port_column(port: Port, values, where: str) -> np.ndarray:
    """One input's column of a block, checked: whole numbers in its shape."""
    try:
        column = np.asarray(values)
    except (TypeError, ValueError):
        column = np.asarray([])
    if column.dtype != np.int64 and (column.dtype == bool or not np.issubdtype(column.dtype, np.integer)):
        raise InputError(f"{where}: column {port.name} must hold whole numbers, got {column.dtype}")
    shape_ok = column.ndim == 2 and column.shape[1] == len(port.places) if port.table else column.ndim == 1
    if not shape_ok:
        raise InputError(f"{where}: column {port.name} must be " + (
            f"n rows of {len(port.places)} bytes" if port.table else "one value per case (1-D)"))
    return column


def _check_column_fits(port: Port, column: np.ndarray, where: str, extremes: tuple[int, int] | None = None) -> None:
    """Every value of the column within the port's width (`extremes`: its least and greatest value, known)."""
    limit = 1 << (8 if port.table else port.bits)
    if not column.size:
        return
    row = one_row(column)
    if row is not None:  # one row repeated: its values are the column's
        column = row
    if extremes is None:
        if column.dtype == np.int64 and column.view(np.uint64).max() < limit:  # one pass: a negative is huge there
            return
        extremes = (column.min(), column.max())
    if extremes[0] < 0 or extremes[1] >= limit:
        bad = extremes[0] if extremes[0] < 0 else extremes[1]
        raise InputError(f"{where}: column {port.name} holds {int(bad)}, which does not fit in {port.describe()} "
                         f"(0..{limit - 1})")


def _checked(routine: Routine, key: str, made, expected: int | None = None) -> Iterator[tuple]:
    """Cases from a spec's function, normalised to tuples and checked against the inputs' widths."""
    names = routine.input_names
    where = f"{routine.spec_path}: {key}"
    try:
        iterator = iter(made)
    except TypeError:
        raise InputError(f"{where}: the function must return a list or iterable of cases, "
                         f"got {type(made).__name__}") from None
    produced = 0
    for chunk in chunks(iterator):
        cases = [_normalise(case, names, where) for case in chunk]
        _check_widths(routine, cases, where)
        produced += len(cases)
        yield from cases
    if expected is not None and produced != expected:
        raise InputError(f"{where}: asked for {expected} cases, the function returned {produced}")


def _normalise(case, names: tuple[str, ...], where: str) -> tuple:
    if isinstance(case, dict):
        wrong = _wrong_names(case, names)
        if wrong:
            raise InputError(f"{where}: case {_short(case)} {wrong}")
        case = tuple(case[n] for n in names)
    elif isinstance(case, np.ndarray):
        case = tuple(case.tolist())
    elif not isinstance(case, (tuple, list)):
        raise InputError(f"{where}: a case must be a tuple in the inputs' order or a dict by name, got {_short(case)}")
    if len(case) != len(names):
        raise InputError(f"{where}: case {_short(case)} has {len(case)} values for {len(names)} inputs "
                         f"({', '.join(names)})")
    return tuple(tuple(int(b) for b in v) if isinstance(v, (list, tuple, bytes, bytearray, np.ndarray))
                 else v for v in case)


def _check_widths(routine: Routine, cases: list[tuple], where: str) -> None:
    for index, port in enumerate(routine.inputs):
        column = [case[index] for case in cases]
        if port.table:
            size = len(port.places)
            for case, value in zip(cases, column):
                if not isinstance(value, tuple) or len(value) != size or not all(
                        isinstance(b, int) and 0 <= b <= 0xFF for b in value):
                    raise InputError(f"{where}: case {_short(case)}: {port.name} must be {size} bytes (0..255)")
            continue
        try:
            values = np.asarray(column, dtype=np.int64)
        except (TypeError, ValueError, OverflowError):
            bad = next(c for c in cases if not isinstance(c[index], (int, np.integer)) or isinstance(c[index], bool)
                       or not -2**63 <= c[index] < 2**63)
            raise InputError(f"{where}: case {_short(bad)}: {port.name} must be a whole number") from None
        limit = 1 << port.bits
        wrong = np.flatnonzero((values < 0) | (values >= limit))
        if len(wrong):
            case = cases[int(wrong[0])]
            raise InputError(f"{where}: case {_short(case)}: {port.name} = {case[index]} does not fit in "
                             f"{port.describe()} (0..{limit - 1})")
        for i, v in enumerate(column):  # numpy integers become plain ints (JSON, hashing, shifts)
            if type(v) is not int:
                if isinstance(v, float) or isinstance(v, bool):
                    raise InputError(f"{where}: case {_short(cases[i])}: {port.name} must be a whole number")
                cases[i] = cases[i][:index] + (int(v),) + cases[i][index + 1:]


def _short(value) -> str:
    return shown(value, 80)
