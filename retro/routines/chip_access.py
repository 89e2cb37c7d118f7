"""Whether a routine's calls can run on the batched core with a chip scene, and the cycles the chip
steals from each lane there.

The batched core models no chips. A routine whose calls never touch a chip register still runs on
a chip's timeline: the VIC-II takes the bus on Bad Lines and for sprite DMA, and that depends only
on the beam position and the register state, which such a routine cannot change. So its calls can
run on the batched core with each instruction's stall added per lane (`BusStalls`), exactly as
`retro.cpu.mpu.MPU6510.step_timed` counts it, as long as no interrupt can come.

`chip_free(...)` decides from the routine's code, statically, and says why. It is conservative:
when unsure, the answer is no (Machine runs the calls):
- every instruction reachable from the entry is decoded (`retro.cpu.flow.decode`); an indirect jump,
  RTI, BRK, or a JSR out of the program make the code unknown;
- an access with an absolute address (indexed: the 256 bytes from the base) that reaches a page a
  chip owns touches the chip; an indirect access ((zp,X), (zp),Y, (zp)) might reach anything;
- a store whose absolute address range meets the routine's own code could rewrite an operand;
- more pushes (PHA, PHP) than pulls, or TXS, could make an RTS jump where the decoder did not look;
- with interrupt sources enabled in the scene, an IRQ could come unless I is set on entry and no
  CLI, PLP or RTI is in the code.
"""

from __future__ import annotations

import numpy as np

from retro.cpu.flow import decode
from retro.cpu.timing import timing_of
from retro.errors import InputError

PAGE_SHIFT = 8
INDEXED_REACH = 0xFF  # abs,X / abs,Y reach up to 255 bytes past the base
INDIRECT_MODES = frozenset({"inx", "iny", "zpi", "ind", "iax"})
ABSOLUTE_MODES = frozenset({"abs", "abx", "aby"})
STORE_MNEMONICS = frozenset({"STA", "STX", "STY", "SAX", "STZ", "INC", "DEC", "ASL", "LSR", "ROL", "ROR",
                             "SLO", "RLA", "SRE", "RRA", "DCP", "ISC", "TSB", "TRB"})
PUSHES, PULLS = frozenset({"PHA", "PHP", "PHX", "PHY"}), frozenset({"PLA", "PLP", "PLX", "PLY"})
FREE_REASON = "the routine touches no chip register"
CLEARS_I = frozenset({"CLI", "PLP", "RTI"})
FLOW_MNEMONICS = frozenset({"JMP", "JSR"})


def chip_free(read, entry: int, program: tuple[int, int], chip_pages: frozenset[int], cpu: str,
              interrupts: bool) -> tuple[bool, str]:
    """(whether no call can touch a chip register or be interrupted, why) -- module docstring.
    `program` is (first, end) of the program's bytes, `chip_pages` the pages chips own,
    `interrupts` whether the chip has an interrupt source enabled (the caller has checked that I
    is set on entry)."""
    outside: list[int] = []

    def note_call(pc: int, target: int) -> tuple[int, int]:
        if not program[0] <= target < program[1]:
            outside.append(target)
        return (0, 0)

    code: dict[int, int] = {}
    pending, seen = [entry], set()
    while pending:
        start = pending.pop()
        if start in seen:
            continue
        seen.add(start)
        before = len(outside)
        try:
            nodes = decode(read, start, note_call, cpu)
        except (InputError, KeyError, ValueError) as exc:
            return False, f"the code is not followed statically ({exc})"
        if len(outside) > before:
            return False, f"a JSR leaves the program (to ${outside[-1]:04X})"
        for pc in nodes:
            code[pc] = timing_of(read(pc), cpu).length
            if read(pc) == 0x20:  # JSR: the callee is code too
                pending.append(read(pc + 1) | read(pc + 2) << 8)
    pushes = pulls = 0
    mnemonics = set()
    for pc, length in sorted(code.items()):
        op = timing_of(read(pc), cpu)
        mnemonics.add(op.mnemonic)
        pushes += op.mnemonic in PUSHES
        pulls += op.mnemonic in PULLS
        if op.mnemonic == "TXS":
            return False, f"TXS at ${pc:04X} (the stack is moved: returns are not followed)"
        if op.mode in INDIRECT_MODES:
            return False, f"an indirect access at ${pc:04X} might reach a chip register"
        if op.mode not in ABSOLUTE_MODES or op.mnemonic in FLOW_MNEMONICS:
            continue
        base = read(pc + 1) | read(pc + 2) << 8
        last = base + (INDEXED_REACH if op.mode != "abs" else 0)
        if any(page & 0xFF in chip_pages for page in range(base >> PAGE_SHIFT, (last >> PAGE_SHIFT) + 1)):
            return False, f"the access at ${pc:04X} reaches a chip register"
        if op.mnemonic in STORE_MNEMONICS and any(base <= p + k <= last for p, n in code.items() for k in range(n)):
            return False, f"the store at ${pc:04X} may rewrite the routine's own code"
    if pushes > pulls:
        return False, "more pushes than pulls: an RTS may jump where the decoder did not look"
    if interrupts and mnemonics & CLEARS_I:
        return False, f"the scene enables interrupts and the code has {'/'.join(sorted(mnemonics & CLEARS_I))}"
    return True, f"{FREE_REASON} (checked from its code)"


class BusStalls:
    """The cycles the VIC-II holds the CPU during one instruction, per lane: `stalls(opcode, begin,
    spent)` for lanes whose instruction began `begin` cycles into the call and took `spent` cycles
    without stalls; the call starts at frame time `start` of a chip whose BA schedule is `wait`
    (retro.chips.vic.dma.BusSchedule.wait). The same count as MPU6510.stall_before: each read
    cycle waits while BA is low, write cycles (`write_masks`, bit i: cycle i writes) go on."""

    def __init__(self, wait, start: int, write_masks: list[int]) -> None:
        self.wait = np.asarray(wait, dtype=np.int64)
        self.frame = len(self.wait)
        self.start = start
        self.write_masks = write_masks
        self._tables: dict[tuple[int, int], np.ndarray] = {}

    def _table(self, cycles: int, mask: int) -> np.ndarray:
        """The stall of an instruction of `cycles` cycles (write mask `mask`) begun at each frame time."""
        key = (cycles, mask)
        table = self._tables.get(key)
        if table is None:
            t = np.arange(self.frame)
            table = np.zeros(self.frame, dtype=np.int64)
            for i in range(cycles):
                if not mask >> i & 1:
                    table += self.wait[(t + i + table) % self.frame]
            self._tables[key] = table
        return table

    def __call__(self, opcode: int, begin: np.ndarray, spent: np.ndarray) -> np.ndarray:
        mask = self.write_masks[opcode]
        at = (self.start + begin) % self.frame
        first = int(spent[0])
        if (spent == first).all():
            return self._table(first, mask)[at]
        out = np.empty(len(begin), dtype=np.int64)
        for cycles in np.unique(spent).tolist():
            chosen = spent == cycles
            out[chosen] = self._table(int(cycles), mask)[at[chosen]]
        return out
