"""Whether a routine's calls can run on the batched core with a chip scene, and the cycles the chip
steals from each lane there.

The batched core models no chips. A routine whose calls never touch a chip register still runs on
a chip's timeline: the VIC-II takes the bus on Bad Lines and for sprite DMA, and that depends only
on the beam position and the register state, which such a routine cannot change. So its calls can
run on the batched core with each instruction's stall added per lane (`BusStalls`), exactly as
`retro.cpu.mpu.MPU6510.step_timed` counts it, as long as no interrupt can come.

`chip_free(...)` decides from the routine's code, statically, and says why. It is conservative:
when unsure, the answer is no (Machine runs the calls):
- every instruction reachable from the entry is decoded (`retro.cpu.flow.decode`) up to its RTS (an
  interrupt handler's: RTS or RTI); an indirect jump, any other RTI, BRK, or a JSR out of the program
  make the code unknown;
- an access with an absolute address (indexed: the 256 bytes from the base) that reaches a page a
  chip owns touches the chip; an indirect access ((zp,X), (zp),Y, (zp)) might reach anything;
- a store whose absolute address range meets the routine's own code could rewrite an operand;
- more pushes (PHA, PHP) than pulls, or TXS, could make an RTS jump where the decoder did not look;
- with interrupt sources enabled in the scene, an IRQ could come unless I is set on entry and no
  CLI, PLP or RTI is in the code (a handler's own closing RTI ends the call: it does not count).

On a NES scene (`NesStart`, `NesCalls`) the PPU steals cycles only through OAM DMA, which takes a
write to $4014, a chip register: a routine that touches none runs on the batched core with no stall
at all. The NMI cannot be masked: with $2000 bit 7 set in the scene, a call that could run until the
next vblank flag (its cycle limit reaches it) stays on Machine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from retro.cpu.flow import decode, return_opcodes
from retro.cpu.timing import timing_of
from retro.errors import InputError
from retro.machines.nes import FrameEntry, cycles_to_nmi, enter_frame, frame_entry, nmi_entry, ppu_of
from retro.scenes.nes import NesScene

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
OPCODE_JSR = 0x20


def chip_free(read, entry: int, program: tuple[int, int], chip_pages: frozenset[int], cpu: str,
              interrupts: bool, handler: bool = False) -> tuple[bool, str]:
    """(whether no call can touch a chip register or be interrupted, why) -- module docstring.
    `program` is (first, end) of the program's bytes, `chip_pages` the pages chips own,
    `interrupts` whether the chip has an interrupt source enabled (the caller has checked that I
    is set on entry), `handler` whether the entry is an interrupt handler (its RTI returns)."""
    code, unknown = _reachable_code(read, entry, program, cpu, return_opcodes(handler))
    if unknown:
        return False, unknown
    mnemonics: set[str] = set()
    for pc in sorted(code):
        op = timing_of(read(pc), cpu)
        if not (handler and op.mnemonic == "RTI"):  # the handler's return ends the call, I and all
            mnemonics.add(op.mnemonic)
        reason = _access_problem(read, pc, op, code, chip_pages)
        if reason:
            return False, reason
    return _stack_and_interrupts(read, code, cpu, interrupts, mnemonics)


def _reachable_code(read, entry: int, program: tuple[int, int], cpu: str,
                    ends: frozenset[int]) -> tuple[dict[int, int], str]:
    """{address: length} of every instruction reachable from `entry` (JSR callees included) up to the
    opcodes that return (`ends`), or why the code cannot be followed statically."""
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
        try:
            nodes = decode(read, start, note_call, cpu, ends if start == entry else return_opcodes(False))
        except (InputError, KeyError, ValueError) as exc:
            return code, f"the code is not followed statically ({exc})"
        if outside:
            return code, f"a JSR leaves the program (to ${outside[-1]:04X})"
        for pc in nodes:
            code[pc] = timing_of(read(pc), cpu).length
            if read(pc) == OPCODE_JSR:  # the callee is code too
                pending.append(read(pc + 1) | read(pc + 2) << 8)
    return code, ""


def _access_problem(read, pc: int, op, code: dict[int, int], chip_pages: frozenset[int]) -> str:
    """Why the instruction at `pc` keeps the calls off the batched core ('' when it does not)."""
    if op.mnemonic == "TXS":
        return f"TXS at ${pc:04X} (the stack is moved: returns are not followed)"
    if op.mode in INDIRECT_MODES:
        return f"an indirect access at ${pc:04X} might reach a chip register"
    if op.mode not in ABSOLUTE_MODES or op.mnemonic in FLOW_MNEMONICS:
        return ""
    base = read(pc + 1) | read(pc + 2) << 8
    last = base + (INDEXED_REACH if op.mode != "abs" else 0)
    if any(page & 0xFF in chip_pages for page in range(base >> PAGE_SHIFT, (last >> PAGE_SHIFT) + 1)):
        return f"the access at ${pc:04X} reaches a chip register"
    if op.mnemonic in STORE_MNEMONICS and any(base <= p + k <= last for p, n in code.items() for k in range(n)):
        return f"the store at ${pc:04X} may rewrite the routine's own code"
    return ""


def _stack_and_interrupts(read, code: dict[int, int], cpu: str, interrupts: bool,
                          mnemonics: set[str]) -> tuple[bool, str]:
    """The verdict once no single instruction was a problem: pushes against pulls, interrupts."""
    pushes = sum(timing_of(read(pc), cpu).mnemonic in PUSHES for pc in code)
    pulls = sum(timing_of(read(pc), cpu).mnemonic in PULLS for pc in code)
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


@dataclass(frozen=True)
class NesStart:
    """Run every call with a NES scene's PPU on the bus, entered at `line` and `dot` of the frame, or
    (`in_nmi`) where an NMI handler starts (retro.machines.nes.nmi_entry); the frame drawn so far in
    the PPU's flags (vblank, sprite-0 hit, overflow), as the hardware has them then."""

    scene: NesScene
    line: int = 0
    dot: int = 0
    in_nmi: bool = False

    def entry(self, enter: str) -> FrameEntry:
        """Where a call starts; `enter` is the routine's ("nmi": its cycles count the interrupt sequence,
        which then begins at the vblank flag)."""
        if self.in_nmi:
            return nmi_entry(self.scene.video, sequence_counted=enter == "nmi")
        return frame_entry(self.scene.video, self.line, self.dot)


class NesCalls:
    """The PPU side of a routine's calls on a NES scene: each call from the same beam position and the
    same PPU state (what earlier calls wrote, read or copied by DMA is forgotten), and the cycles OAM
    DMA held the CPU in the last one."""

    def __init__(self, machine, start: NesStart, enter: str) -> None:
        self.machine = machine
        self.ppu = ppu_of(machine)
        self.entry = start.entry(enter)
        self.handler = enter != "jsr"
        enter_frame(machine, self.entry)
        self.ppu.dma_stalled = 0
        self._snapshot = self.ppu.snapshot()

    def restart(self) -> None:
        """The PPU as the call's entry finds it, its clock set so that the machine's next cycle is the entry's."""
        self.ppu.restore(self._snapshot, self.machine.cycle - self.entry.cycle)

    @property
    def dma_cycles(self) -> int:
        """Cycles OAM DMA held the CPU since the last `restart`."""
        return self.ppu.dma_stalled

    def verdict(self, read, entry: int, program: tuple[int, int], cpu: str, limit: int) -> tuple[bool, str]:
        """Whether the batched core may run the calls (no stall can happen) and why (module docstring)."""
        pages = frozenset(page for page, device in enumerate(self.machine.bus.page_devices) if device is not None)
        free, why = chip_free(read, entry, program, pages, cpu, False, self.handler)
        if not free:
            return False, why
        to_nmi = cycles_to_nmi(self.ppu, self.entry)
        if to_nmi is not None and limit >= to_nmi:
            return False, (f"the scene enables the NMI ($2000 bit 7) and a call may run {limit:,} cycles, past the "
                           f"next vblank flag {to_nmi:,} cycles after its start")
        return True, why
