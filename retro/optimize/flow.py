"""Rewrites of a routine's control flow: jumps and branches that could fall through, and blocks
placed where a jump to them was. Each rewrite keeps every path's instructions and only removes
jumps, inverts a branch or moves a block, so it is a candidate like any other: run on the samples
and proven on the whole routine before it is kept (retro.optimize.optimizer); a branch that no
longer reaches its target makes the listing fail to assemble and the candidate is dropped.

The rewrites (`rewrites`):
- a JMP or a conditional branch to the next instruction is dropped;
- `Bxx skip / JMP far / skip:` becomes `B(not xx) far` (the branch over a jump falls through);
- a branch or JMP to a JMP goes straight to that JMP's target; a JMP to an RTS becomes the RTS;
- `JMP there` where `there` starts a block no instruction falls into (the one before it ends its
  path) and that ends its own path: the block moves to where the JMP was;
- `JMP there` over blocks no instruction falls into, the last of which ends its path: those blocks
  move to the routine's end, and the JMP falls through.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace

from retro.optimize.code import ENDS, Instruction, Listing

INVERSE = {"BCC": "BCS", "BCS": "BCC", "BEQ": "BNE", "BNE": "BEQ", "BMI": "BPL", "BPL": "BMI", "BVC": "BVS",
           "BVS": "BVC"}


@dataclass(frozen=True)
class Row:
    """One instruction with the labels just before it."""

    labels: tuple[str, ...]
    instruction: Instruction


def _rows(listing: Listing) -> tuple[list[Row], tuple[str, ...]]:
    """The listing as rows, and the labels after its last instruction."""
    rows = [Row(tuple(listing.label_at(k)), i) for k, i in enumerate(listing.instructions)]
    return rows, tuple(listing.label_at(len(listing.instructions)))


def _listing(origin: int, rows: list[Row], trailing: tuple[str, ...]) -> Listing:
    labels = [(name, k) for k, row in enumerate(rows) for name in row.labels]
    labels += [(name, len(rows)) for name in trailing]
    return Listing(origin, tuple(row.instruction for row in rows), tuple(sorted(labels, key=lambda kv: (kv[1], kv[0]))))


def _dropped(rows: list[Row], trailing: tuple[str, ...], k: int) -> tuple[list[Row], tuple[str, ...]]:
    """Row k removed; its labels move to the row after it (or the end)."""
    labels = rows[k].labels
    rest = rows[:k] + rows[k + 1:]
    if k < len(rest):
        rest[k] = replace(rest[k], labels=labels + rest[k].labels)
        return rest, trailing
    return rest, labels + trailing


def _ends_path(instruction: Instruction) -> bool:
    return instruction.mnemonic in ENDS


def _local(instruction: Instruction) -> bool:
    """A branch or JMP to a label of the routine."""
    return isinstance(instruction.target, str) and (instruction.is_branch or instruction.mnemonic == "JMP")


def _block_end(rows: list[Row], start: int) -> int | None:
    """The index of the first row from `start` that ends its path (RTS, JMP, ...), or None."""
    for k in range(start, len(rows)):
        if _ends_path(rows[k].instruction):
            return k
    return None


def _falls_into(rows: list[Row], k: int) -> bool:
    """Whether the instruction before row k can go on to it."""
    return k == 0 or not _ends_path(rows[k - 1].instruction)


def rewrites(listing: Listing) -> Iterator[tuple[str, Listing]]:
    """(what, new listing) for every flow rewrite that applies (see the module's docstring)."""
    rows, trailing = _rows(listing)
    where = dict(listing.labels)
    origin = listing.origin
    for k, row in enumerate(rows):
        instruction = row.instruction
        if not _local(instruction):
            continue
        target = where[instruction.target]
        if target == k + 1:
            yield f"{instruction.mnemonic} to the next instruction dropped", _listing(origin, *_dropped(rows, trailing, k))
            continue
        if (instruction.is_branch and instruction.mnemonic in INVERSE and k + 1 < len(rows) and target == k + 2
                and rows[k + 1].instruction.mnemonic == "JMP" and _local(rows[k + 1].instruction)
                and not rows[k + 1].labels):
            inverted = Instruction(INVERSE[instruction.mnemonic], "rel", target=rows[k + 1].instruction.target)
            new = rows[:k] + [Row(row.labels, inverted)] + rows[k + 1:]
            yield "a branch over a JMP inverted", _listing(origin, *_dropped(new, trailing, k + 1))
        if target < len(rows):
            landing = rows[target].instruction
            if _local(landing) and landing.mnemonic == "JMP" and landing.target != instruction.target:
                new = list(rows)
                new[k] = replace(row, instruction=replace(instruction, target=landing.target))
                yield "a jump to a JMP sent to its target", _listing(origin, new, trailing)
            if instruction.mnemonic == "JMP" and landing.mnemonic == "RTS":
                new = list(rows)
                new[k] = replace(row, instruction=landing)
                yield "a JMP to an RTS made the RTS", _listing(origin, new, trailing)
        if instruction.mnemonic != "JMP":
            continue
        end = _block_end(rows, target) if target < len(rows) else None
        if end is not None and not _falls_into(rows, target) and not target <= k <= end:
            block = rows[target:end + 1]
            block = [replace(block[0], labels=row.labels + block[0].labels)] + block[1:]
            rest = [r for i, r in enumerate(rows) if not target <= i <= end]
            at = k if k < target else k - len(block)
            new = rest[:at] + block + rest[at + 1:]
            yield "a block moved to the JMP that reached it", _listing(origin, new, trailing)
        if not trailing and k + 1 < target <= len(rows) and _ends_path(rows[target - 1].instruction) and _ends_path(rows[-1].instruction):
            skipped = rows[k + 1:target]
            new = rows[:k + 1] + rows[target:] + skipped
            new, new_trailing = _dropped(new, trailing, k)
            yield "the blocks a JMP went over moved to the end", _listing(origin, new, new_trailing)
