"""The batched core's column blocks: every case once, in order, whatever the parts' block sizes; blocks
of table cases kept within BLOCK_BYTES."""

from __future__ import annotations

import numpy as np

from retro.routines import cases
from retro.routines.cases import BLOCK_BYTES, Part, batches


def part(sizes: list[int], width: int = 0, start: int = 0) -> Part:
    def blocks():
        at = start
        for n in sizes:
            numbers = np.arange(at, at + n, dtype=np.int64)
            block = [numbers]
            if width:
                block.append(np.repeat(numbers[:, None] % 256, width, axis=1))
            at += n
            yield block
    return Part("sweep", sum(sizes), sum(sizes), blocks)


def test_every_case_once_in_order():
    parts = [part([5000, 1, 12000, 7]), part([3], start=17008), part([30000, 2], start=17011)]
    made = list(batches(parts, 4096))
    joined = np.concatenate([block[0] for block in made])
    assert joined.tolist() == list(range(47013))
    assert all(len(block[0]) == 4096 for block in made[:-1]) and 0 < len(made[-1][0]) <= 4096


def test_blocks_of_tables_stay_within_their_byte_budget():
    width = 126  # two 63-byte masks, as the pixel routine takes
    made = list(batches([part([65536, 65536], width=width)], 65536))
    per_case = 8 * (1 + width)
    assert all(sum(c.nbytes for c in block) <= max(BLOCK_BYTES, cases.CHUNK * per_case) for block in made)
    assert len(made[0][0]) == BLOCK_BYTES // per_case
    assert np.concatenate([b[0] for b in made]).tolist() == list(range(131072))
    assert all((b[1] == (b[0][:, None] % 256)).all() for b in made)


def test_a_block_is_a_copy_not_a_view_of_the_parts_block():
    made = list(batches([part([10000])], 4096))
    assert all(block[0].base is None for block in made)
