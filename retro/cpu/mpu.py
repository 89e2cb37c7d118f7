"""The 6502 cores: py65's MPU made cycle-exact, bus-aware, and complete for C64 code.

Three variants:
- `MPU6510` (Commodore 64): NMOS 6502 with decimal mode.
- `MPU2A03` (NES): the same core with decimal mode removed: ADC, SBC and the undocumented
  opcodes built on them (RRA, ISC, ARR) ignore the D flag.
- `MPU65C02` (retro.cpu.mpu65c02): the WDC 65C02, built on MPU6510 from its opcode table.
`retro.cpu.variants` names them (`VARIANTS`, `variant_named`).

What this adds to py65 1.2.0:
- DEC abs ($CE) costs 6 cycles (py65 charges 3).
- The stable undocumented NMOS opcodes that C64 code uses: LAX, SAX, DCP, ISC, SLO, RLA, SRE, RRA,
  ANC, ALR, ARR, SBX, SBC #imm ($EB) and the undocumented NOPs, with their page-crossing penalties.
  Sources: "NMOS 6510 Unintended Opcodes - No More Secrets" (groepaz, 2024) and 64doc
  (J. Ahola et al.) for the operations, decimal-mode ARR/ADC/SBC and the cycle counts.
- The unstable opcodes (SHA, SHX, SHY, TAS, LAS, ANE, LXA) and the twelve JAM opcodes raise
  `CpuHalt`, naming the opcode and its address: their results depend on the chip and temperature.
- Device access timing: when a data read or write lands on a page that a device owns, the device is
  told the CPU cycle of that bus access (cycle count at the start of the instruction plus the offset
  of that bus cycle within it), so chips can be timed against the beam. Plain RAM stays a Python
  list; opcodes and operands are always fetched from it. Dummy reads are not put on the bus.
  docs/cpu.md has the model and what it leaves out.
- BRK optionally stops the run (`stop_on_brk`), which `Machine.call` uses.
- `run`, the one run loop `Machine` uses: stop address and stack, cycle limit, a ring of recent
  instruction addresses for error messages, and an optional observer told before and after each
  step (the trace and the timing model's record of the path). `run_until` is the same loop with
  `step` inlined, taken when nothing observes and no chip drives the control lines; it and the
  cheaper operand fetches make it faster than bare py65.
- `step_timed`, the step `run` takes when a chip drives the CPU's control lines (`lines`, a
  `retro.cpu.bus.CpuLines`; the VIC-II on a C64): RDY/BA stalls and IRQ/NMI. Without such a chip
  none of this code runs, so plain RAM and passive devices cost nothing extra.
  * Stalls [Bauer 3.6.3]: while BA is low the CPU stops at its first read cycle and goes on when BA
    is high again; write cycles go on. Each opcode's write cycles are known (WRITE_CYCLES_FROM_END),
    every other cycle reads (dummy reads included), so the cycles lost depend on the instruction.
    A device access sees the cycle after the stalls before it.
  * Interrupts [64doc; visual6502 wiki "6502 Timing of Interrupt Handling"; VICE's CPU core (an
    interrupt must be asserted 2 cycles before the next opcode fetch)]: the line is polled in the
    penultimate cycle of an instruction (stalls included), so an IRQ asserted by then is taken after
    the instruction, one asserted in its last cycle after the next one. A taken branch that does not
    cross a page polls one cycle earlier (in its first cycle). CLI, SEI and PLP
    change I after the poll (their effect shows one instruction later); RTI restores I before it.
    NMI is edge-triggered and ignores I. The sequence takes 7 cycles (two reads, three pushes, the
    vector from RAM at $FFFE/$FFFF or $FFFA/$FFFB), pushes P with B clear and sets I.
"""

from __future__ import annotations

from py65.devices.mpu6502 import MPU as _Py65MPU
from py65.utils.devices import make_instruction_decorator

from retro.cpu.opcodes import (
    JAM,
    MODE_LENGTH,
    OPCODE_TABLE,
    STABLE,
    UNSTABLE,
    opcodes_of,
)

ADDRESS_MASK = 0xFFFF
PAGE_SHIFT = 8

FLAG_N = 0x80
FLAG_V = 0x40
FLAG_U = 0x20
FLAG_B = 0x10
FLAG_D = 0x08
FLAG_I = 0x04
FLAG_Z = 0x02
FLAG_C = 0x01

OPCODE_BRK = 0x00
OPCODE_CLI, OPCODE_SEI, OPCODE_PLP = 0x58, 0x78, 0x28
BRANCH_OPCODES = frozenset({0x10, 0x30, 0x50, 0x70, 0x90, 0xB0, 0xD0, 0xF0})
I_CHANGED_AFTER_POLL = frozenset({OPCODE_CLI, OPCODE_SEI, OPCODE_PLP})
IRQ_VECTOR = 0xFFFE
NMI_VECTOR = 0xFFFA
RESET_VECTOR = 0xFFFC
INTERRUPT_CYCLES = 7
# Interrupt hijacking [blargg's cpu_interrupts_v2, 2-nmi_and_brk and 3-nmi_and_irq; visual6502 wiki
# "6502 Timing of Interrupt Handling"]: the vector of BRK (and of an IRQ sequence) is chosen late in
# the sequence; an NMI edge a poll in cycle HIJACK_POLL of it (0 = its first) sees takes the NMI
# vector instead (BRK's pushed P keeps B set). The sequence itself does not poll at its end: an NMI
# that comes later is taken after the handler's first instruction. 3 is fitted to 2-nmi_and_brk (its
# ten lines step the NMI one CPU cycle later each: "interrupts BRK for 5 clocks, and occurs after SEC
# in BRK handler for last 2 clocks"); 2 or 4 fail it.
HIJACK_POLL = 3
# 64doc: the cycles in which an instruction writes, counted back from its last cycle (1 = last).
# Every other cycle is a read, dummy reads included, and stops the CPU while BA is low.
_STORES = (0x85, 0x95, 0x8D, 0x9D, 0x99, 0x81, 0x91, 0x86, 0x96, 0x8E, 0x84, 0x94, 0x8C,
           0x87, 0x97, 0x83, 0x8F)
WRITE_CYCLES_FROM_END = {**{op: (1,) for op in _STORES}, 0x48: (1,), 0x08: (1,),  # PHA, PHP
                         0x20: (2, 3), OPCODE_BRK: (3, 4, 5)}  # JSR pushes twice, BRK three times
# (read-modify-write opcodes write in their last two cycles: RMW_OPCODES)
INTERRUPT_WRITES = (3, 4, 5)  # the interrupt sequence pushes PCH, PCL, P like BRK
RECENT_SIZE = 16  # a power of two: run_until keeps the addresses of this many recent instructions
RECENT_MASK = RECENT_SIZE - 1
_KEEP_ALL_BUT_NVZC = 0xFF & ~(FLAG_N | FLAG_V | FLAG_Z | FLAG_C)
_KEEP_ALL_BUT_NZC = 0xFF & ~(FLAG_N | FLAG_Z | FLAG_C)
_KEEP_ALL_BUT_NZ = 0xFF & ~(FLAG_N | FLAG_Z)
# From the opcode table (retro.cpu.opcodes): JAM locks the NMOS CPU until reset; the unstable opcodes'
# results depend on the chip revision, temperature or bus state ("unstable" in No More Secrets).
JAM_OPCODES = frozenset(opcodes_of(JAM))
UNSTABLE_OPCODES = {opcode: row.mnemonic for opcode, row in opcodes_of(UNSTABLE).items()}
UNDOCUMENTED_RMW = ("SLO", "RLA", "SRE", "RRA", "DCP", "ISC")
RMW_MNEMONICS = frozenset({"ASL", "LSR", "ROL", "ROR", "INC", "DEC", *UNDOCUMENTED_RMW})


class CpuHalt(Exception):
    """The CPU met an instruction it will not execute (JAM, unstable opcode, or BRK when stopping)."""

    def __init__(self, kind: str, opcode: int, address: int):
        self.kind = kind
        self.opcode = opcode
        self.address = address
        super().__init__(f"{kind} (opcode ${opcode:02X}) at ${address:04X}")


def _mask(cycles: int, from_end) -> int:
    return sum(1 << (cycles - k) for k in from_end)


def _copy_tables(base):
    return list(base.instruct), list(base.cycletime), list(base.extracycles), list(base.disassemble)


class MPU6510(_Py65MPU):
    """NMOS 6502 as in the C64's 6510 (the I/O port at $00/$01 is not modelled: it is plain RAM)."""

    instruct, cycletime, extracycles, disassemble = _copy_tables(_Py65MPU)
    instruction = make_instruction_decorator(instruct, disassemble, cycletime, extracycles)
    has_decimal = True
    opcode_table = OPCODE_TABLE
    interrupt_clears = 0  # P bits the interrupt sequence clears besides setting I (the 65C02 clears D)
    decimal_extra_cycles = 0  # cycles ADC/SBC add with D set (the 65C02's one)

    # Opcodes whose memory operand is read, modified and written back (read at n-3, the unmodified
    # value written at n-2, the result at n-1, where n is the instruction's cycle count).
    RMW_OPCODES: frozenset[int] = frozenset()

    def __init__(self, memory=None, pc: int = 0x0000, page_devices=None):
        self.page_devices = page_devices if page_devices is not None else [None] * 256
        self.stop_on_brk = False
        self.current_op = 0
        # Addresses of the last RECENT_SIZE instructions started by run_until (a ring, indexed by count).
        self.recent = [0] * RECENT_SIZE
        self.executed = 0  # instructions started by the last run_until, including one that halted
        self.lines = None  # a CpuLines when a chip drives RDY/IRQ/NMI (then run steps with step_timed)
        self.pending_interrupt = None  # "IRQ" or "NMI", decided by the poll of the last instruction
        self.stolen = 0  # cycles lost to stalls since power-on (part of processorCycles)
        self.last_stolen = 0  # of the last step_timed
        self.settled = (0, 0)  # (next cycle index, delay so far) of the instruction being executed
        self.ba_high_until = -1  # BA is known high up to (not including) this cycle
        self.halted_at = -1  # the start of the instruction a DMA (`stall`) halted the CPU after ...
        self.halted = 0  # ... and for how many cycles
        self.modelled = 0  # the timing model's cycles of the last run_recorded
        super().__init__(memory=memory, pc=pc)
        self.name = type(self).__name__[3:]
        # instructions that write have a fixed cycle count: their write cycles are known in advance
        self.write_masks = [self.write_mask(op, self.cycletime[op]) for op in range(256)]

    # ---- execution -------------------------------------------------------------------------

    def step(self):
        """Execute one instruction (run_until is the same cycle, inlined for speed)."""
        pc = self.pc
        op = self.memory[pc]
        self.current_op = op
        self.pc = (pc + 1) & ADDRESS_MASK
        self.excycles = 0
        self.instruct[op](self)
        self.pc &= ADDRESS_MASK
        self.processorCycles += self.cycletime[op] + self.excycles
        return self

    def run_until(self, stop_pc: int, stop_sp: int, limit: int) -> int:
        """Execute until PC == stop_pc (and SP == stop_sp, unless stop_sp < 0) or the clock reaches limit.

        Returns the number of instructions executed; records their addresses in `recent`. The body of
        `step` is inlined here: a method call per instruction would cost over 10% of the speed.
        CpuHalt propagates with `executed` counting the halting instruction.
        """
        memory = self.memory
        instruct = self.instruct
        cycletime = self.cycletime
        recent = self.recent
        count = 0
        try:
            while True:
                pc = self.pc
                if pc == stop_pc and (stop_sp < 0 or self.sp == stop_sp):
                    return count
                if self.processorCycles >= limit:
                    return count
                recent[count & RECENT_MASK] = pc
                count += 1
                op = memory[pc]
                self.current_op = op
                self.pc = (pc + 1) & ADDRESS_MASK
                self.excycles = 0
                instruct[op](self)
                self.pc &= ADDRESS_MASK
                self.processorCycles += cycletime[op] + self.excycles
        finally:
            self.executed = count

    def run_recorded(self, stop_pc: int, stop_sp: int, limit: int, record: list | None,
                     pointer_pcs: frozenset[int], model) -> int:
        """`run_until` that also tells the executed path, for Machine's sweeps of many calls: before each
        instruction, (pc, x, y, P, pointer, a) is appended to `record` (unless None), pointer being the
        zero-page word its operand names when its PC is in `pointer_pcs` (else 0); and the independent
        timing model's count of the path (`model`, a retro.cpu.timing.StepModel: its cycles from the
        opcode, operand bytes, pointer and registers before the instruction, never from this core's cycle
        bookkeeping) is summed into `modelled` as it goes. An opcode the model does not know counts 0:
        the CPU halts on it (JAM, unstable). Without chips on the control lines only (no
        stall, no interrupt): `run` with an observer is the general loop."""
        memory = self.memory
        read = memory.__getitem__
        instruct = self.instruct
        cycletime = self.cycletime
        bases, rules = model.bases, model.rules
        recent = self.recent
        append = None if record is None else record.append
        count = 0
        modelled = 0
        self.modelled = 0
        cycles = self.processorCycles  # (kept here too: no handler sets it without chips on the lines)
        devices = self.page_devices
        ram_only = devices.count(None) == len(devices)
        if ram_only:  # no device on the bus: data reads and writes go straight to RAM (ByteAt and WriteByte's
            self.ByteAt, self.WriteByte = memory.__getitem__, memory.__setitem__  # own path), for this run
        try:
            while True:
                pc = self.pc & ADDRESS_MASK  # (masked here rather than after each instruction)
                if (pc == stop_pc and (stop_sp < 0 or self.sp == stop_sp)) or cycles >= limit:
                    self.pc = pc
                    return count
                recent[count & RECENT_MASK] = pc
                count += 1
                op = memory[pc]
                # the model before the instruction runs, from its registers and memory as they are now
                rule = rules[op]
                modelled += bases[op] if rule is None else bases[op] + rule(read, pc, self.x, self.y, self.p, None)
                if append is not None:
                    if pc in pointer_pcs:
                        zp = memory[(pc + 1) & ADDRESS_MASK]
                        pointer = memory[zp] | memory[(zp + 1) & 0xFF] << 8
                    else:
                        pointer = 0
                    append((pc, self.x, self.y, (self.p | FLAG_U) & ~FLAG_B, pointer, self.a))
                self.current_op = op
                self.pc = (pc + 1) & ADDRESS_MASK
                self.excycles = 0
                instruct[op](self)
                cycles += cycletime[op] + self.excycles
                self.processorCycles = cycles
        finally:
            self.executed = count
            self.modelled = modelled
            if ram_only:
                del self.ByteAt, self.WriteByte

    def recent_addresses(self, count: int) -> list[int]:
        """The addresses of the last min(count, RECENT_SIZE) instructions, oldest first."""
        n = min(count, RECENT_SIZE)
        return [self.recent[i & RECENT_MASK] for i in range(count - n, count)]

    # ---- control lines: RDY stalls and interrupts (only with `lines` set) -----------------------

    def write_mask(self, op: int, cycles: int) -> int:
        """Bit i set: cycle i (0 = the opcode fetch) of this instruction is a write."""
        from_end = (1, 2) if op in self.RMW_OPCODES else WRITE_CYCLES_FROM_END.get(op, ())
        return _mask(cycles, from_end)

    def stall_before(self, start: int, cycles: int, writes: int, last: int, first: int = 0, delay: int = 0) -> int:
        """Cycles the CPU waits up to cycle `last` of an instruction of `cycles` cycles begun at `start`,
        given `delay` already waited before cycle `first`."""
        lines = self.lines
        if delay == 0 and lines.ba_free(start + first) >= cycles - first:
            return 0
        ba_wait = lines.ba_wait
        for i in range(first, last + 1):
            if not writes >> i & 1:
                delay += ba_wait(start + i + delay)
        return delay

    def step_timed(self) -> bool:
        """Run one instruction, or the interrupt sequence the last poll decided; True for an instruction."""
        start = self.processorCycles
        kind = self.pending_interrupt
        if kind is not None:
            self.pending_interrupt = None
            self._interrupt(kind, start)
            return False
        pc = self.pc
        op = self.memory[pc]
        self.current_op = op
        i_before = self.p & FLAG_I
        self.pc = (pc + 1) & ADDRESS_MASK
        self.excycles = 0
        self.settled = (0, 0)
        self.instruct[op](self)
        self.pc &= ADDRESS_MASK
        cycles = self.cycletime[op] + self.excycles
        # the cycles up to the last device access were settled when it happened, against the bus
        # schedule of that moment (a write to the VIC-II can change BA only for later cycles)
        first, delay = self.settled
        if delay or start + cycles > self.ba_high_until:
            if not delay:
                self.ba_high_until = start + self.lines.ba_free(start)
            delay = self.stall_before(start, cycles, self.write_masks[op], cycles - 1, first, delay)
        end = start + cycles + delay
        self.processorCycles = end
        self.stolen += delay
        self.last_stolen = delay
        lines = self.lines
        if op == OPCODE_BRK:
            self._hijack(start + delay)
            return True
        # the poll: penultimate cycle; a taken branch within its page polls a cycle earlier
        poll = end - 3 if op in BRANCH_OPCODES and self.excycles == 1 else end - 2
        if start == self.halted_at:
            poll -= self.halted  # the DMA came after the poll (`stall`)
        masked = (i_before if op in I_CHANGED_AFTER_POLL else self.p & FLAG_I)
        if poll >= lines.nmi_next and lines.nmi_edge(poll):
            self.pending_interrupt = "NMI"
        elif not masked and poll >= lines.irq_next and lines.irq_low(poll):
            self.pending_interrupt = "IRQ"
        return True

    def _interrupt(self, kind: str, start: int) -> None:
        delay = self.stall_before(start, INTERRUPT_CYCLES, _mask(INTERRUPT_CYCLES, INTERRUPT_WRITES),
                                  INTERRUPT_CYCLES - 1)
        self.stPushWord(self.pc)
        self.stPush((self.p | FLAG_U) & ~FLAG_B)
        self.p = (self.p | FLAG_I) & ~self.interrupt_clears
        vector = NMI_VECTOR if kind == "NMI" else IRQ_VECTOR
        self.pc = self.memory[vector] | self.memory[vector + 1] << 8
        if kind == "IRQ":
            self._hijack(start + delay)
        self.processorCycles = start + INTERRUPT_CYCLES + delay
        self.stolen += delay
        self.last_stolen = delay

    def _hijack(self, start: int) -> None:
        """After BRK or an IRQ sequence begun at `start` (stalls before it counted): an NMI seen by
        cycle HIJACK_POLL takes the vector (HIJACK_POLL above)."""
        poll = start + HIJACK_POLL
        lines = self.lines
        if poll >= lines.nmi_next and lines.nmi_edge(poll):
            self.pc = self.memory[NMI_VECTOR] | self.memory[NMI_VECTOR + 1] << 8

    def run(self, stop_pc: int, stop_sp: int, limit: int, observer=None) -> int:
        """The run loop: execute until PC == stop_pc (and SP == stop_sp, unless stop_sp < 0) or the clock
        reaches limit; return the instructions executed (interrupt sequences are not instructions).

        Each step is an instruction, or the interrupt sequence when one is pending (with a chip on
        the control lines, `step_timed`). An observer (a trace, a record of the path) is told before
        and after every step: `observer.before(mpu)` and `observer.after(mpu)`. Without an observer
        or control lines the loop is `run_until`, the same loop with `step` inlined for speed.
        CpuHalt propagates with `executed` counting the halting instruction.
        """
        if observer is None and self.lines is None:
            return self.run_until(stop_pc, stop_sp, limit)
        recent = self.recent
        step = self.step if self.lines is None else self.step_timed
        count = 0
        try:
            while True:
                pc = self.pc
                if pc == stop_pc and (stop_sp < 0 or self.sp == stop_sp):
                    return count
                if self.processorCycles >= limit:
                    return count
                if self.pending_interrupt is None:
                    recent[count & RECENT_MASK] = pc
                    count += 1
                    self.executed = count
                if observer is None:
                    step()
                else:
                    observer.before(self)
                    step()
                    observer.after(self)
        finally:
            self.executed = count

    def stall(self, cycles: int) -> None:
        """Add cycles to the current instruction (the CPU halted by DMA after it). They come after
        its interrupt poll: an IRQ asserted during OAM DMA is taken after the instruction that follows
        it (blargg's cpu_interrupts_v2 4-irq_and_dma)."""
        self.excycles += cycles
        self.halted_at = self.processorCycles
        self.halted = cycles

    # ---- instruction stream ------------------------------------------------------------------
    # Opcodes and operands are fetched from RAM (the bus's memory list), never from a device:
    # devices see data accesses only. This also makes operand fetches cheaper than py65's.

    def ImmediateByte(self):
        return self.memory[self.pc]

    def ZeroPageAddr(self):
        return self.memory[self.pc]

    def ZeroPageXAddr(self):
        return (self.x + self.memory[self.pc]) & 0xFF

    def ZeroPageYAddr(self):
        return (self.y + self.memory[self.pc]) & 0xFF

    def AbsoluteAddr(self):
        memory = self.memory
        pc = self.pc
        return memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8

    def _indexed(self, base: int, index: int) -> int:
        address = (base + index) & ADDRESS_MASK
        if (base ^ address) & 0xFF00 and self.extracycles[self.current_op]:
            self.excycles += 1  # the page-crossing penalty of reads (stores and RMW have none)
        return address

    def AbsoluteXAddr(self):
        memory = self.memory
        pc = self.pc
        return self._indexed(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8, self.x)

    def AbsoluteYAddr(self):
        memory = self.memory
        pc = self.pc
        return self._indexed(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8, self.y)

    # The zero-page pointer of (zp,X) and (zp),Y is data: read through the bus, wrapping in page 0.
    def IndirectXAddr(self):
        pointer = (self.memory[self.pc] + self.x) & 0xFF
        return self.ByteAt(pointer) | self.ByteAt((pointer + 1) & 0xFF) << 8

    def IndirectYAddr(self):
        pointer = self.memory[self.pc]
        base = self.ByteAt(pointer) | self.ByteAt((pointer + 1) & 0xFF) << 8
        return self._indexed(base, self.y)

    # ---- bus -------------------------------------------------------------------------------

    def _access_cycle(self, from_end: int) -> int:
        op = self.current_op
        cycles = self.cycletime[op] + self.excycles
        if self.lines is None:
            return self.processorCycles + cycles - from_end
        # stalls in the cycles up to and including this access delay it
        start = self.processorCycles
        index = cycles - from_end
        self.ba_high_until = -1  # the access may change when the bus is taken
        first, delay = self.settled
        if index >= first:
            delay = self.stall_before(start, cycles, self.write_masks[op], index, first, delay)
            self.settled = (index + 1, delay)
        return start + index + delay

    def ByteAt(self, addr):
        device = self.page_devices[addr >> PAGE_SHIFT]
        if device is None:
            return self.memory[addr]
        from_end = 3 if self.current_op in self.RMW_OPCODES else 1
        return device.read(addr, self._access_cycle(from_end))

    def WriteByte(self, addr: int, value: int) -> None:
        device = self.page_devices[addr >> PAGE_SHIFT]
        if device is None:
            self.memory[addr] = value
        else:
            device.write(addr, value, self._access_cycle(1))

    def _write_back(self, addr: int, old: int, new: int) -> None:
        """The RMW double write: the unmodified value one cycle before the result."""
        device = self.page_devices[addr >> PAGE_SHIFT]
        if device is None:
            self.memory[addr] = new
        else:
            device.write(addr, old, self._access_cycle(2))
            device.write(addr, new, self._access_cycle(1))

    # ---- py65's commonest operations, each in one frame (the same results: the CPU test vectors) ---

    def FlagsNZ(self, value):
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)

    def opLDA(self, x):
        self.a = value = self.ByteAt(x())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)

    def opLDX(self, y):
        self.x = value = self.ByteAt(y())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)

    def opLDY(self, x):
        self.y = value = self.ByteAt(x())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)

    def opAND(self, x):
        self.a = value = self.a & self.ByteAt(x())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)

    def opORA(self, x):
        self.a = value = self.a | self.ByteAt(x())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)

    def opEOR(self, x):
        self.a = value = self.a ^ self.ByteAt(x())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)

    def opCMPR(self, get_address, register_value):
        diff = register_value - self.ByteAt(get_address())
        self.p = (self.p & _KEEP_ALL_BUT_NZC) | (diff & FLAG_N) | (FLAG_Z if diff == 0 else 0) \
            | (FLAG_C if diff >= 0 else 0)

    def BranchRelAddr(self):
        """A taken branch: one cycle more, and one more again when the target lies in another page
        than the next instruction (PC is at the offset byte here)."""
        offset = self.memory[self.pc]
        after = self.pc + 1
        target = after + (offset - 256 if offset & FLAG_N else offset)
        self.excycles += 2 if (after ^ target) & 0xFF00 else 1
        self.pc = target & ADDRESS_MASK

    # ---- py65 operations that write memory, rerouted through the bus ------------------------

    def opSTA(self, x):
        self.WriteByte(x(), self.a)

    def opSTX(self, y):
        self.WriteByte(y(), self.x)

    def opSTY(self, x):
        self.WriteByte(x(), self.y)

    def _rmw(self, x, operation):
        if x is None:
            self.a = operation(self.a)
            return
        addr = x()
        old = self.ByteAt(addr)
        self._write_back(addr, old, operation(old))

    def opASL(self, x):
        self._rmw(x, self._asl)

    def opLSR(self, x):
        self._rmw(x, self._lsr)

    def opROL(self, x):
        self._rmw(x, self._rol)

    def opROR(self, x):
        self._rmw(x, self._ror)

    def opINCR(self, x):
        self._rmw(x, self._inc)

    def opDECR(self, x):
        self._rmw(x, self._dec)

    # ---- ALU helpers (value in, value out, flags set) -----------------------------------------

    def _nz(self, value: int) -> int:
        self.p = (self.p & ~(FLAG_N | FLAG_Z)) | (value & FLAG_N) | (0 if value else FLAG_Z)
        return value

    def _asl(self, v: int) -> int:
        self.p = (self.p & ~FLAG_C) | (v >> 7)
        return self._nz((v << 1) & 0xFF)

    def _lsr(self, v: int) -> int:
        self.p = (self.p & ~FLAG_C) | (v & 1)
        return self._nz(v >> 1)

    def _rol(self, v: int) -> int:
        carry_in = self.p & FLAG_C
        self.p = (self.p & ~FLAG_C) | (v >> 7)
        return self._nz(((v << 1) | carry_in) & 0xFF)

    def _ror(self, v: int) -> int:
        carry_in = self.p & FLAG_C
        self.p = (self.p & ~FLAG_C) | (v & 1)
        return self._nz((v >> 1) | (carry_in << 7))

    def _inc(self, v: int) -> int:
        return self._nz((v + 1) & 0xFF)

    def _dec(self, v: int) -> int:
        return self._nz((v - 1) & 0xFF)

    def _compare(self, register: int, v: int) -> None:
        diff = register - v
        self.p = (self.p & ~FLAG_C) | (FLAG_C if diff >= 0 else 0)
        self._nz(diff & 0xFF)

    def _decimal_on(self) -> bool:
        return self.has_decimal and bool(self.p & FLAG_D)

    def _adc(self, v: int) -> None:
        a = self.a
        p = self.p
        carry = p & FLAG_C
        binary = a + v + carry
        if not (p & FLAG_D and self.has_decimal):
            result = binary & 0xFF
            p = (p & _KEEP_ALL_BUT_NVZC) | (result & FLAG_N) | (0 if result else FLAG_Z)
            if binary > 0xFF:
                p |= FLAG_C
            if ~(a ^ v) & (a ^ binary) & 0x80:
                p |= FLAG_V
            self.p = p
            self.a = result
            return
        # NMOS decimal ADC (64doc): Z from the binary sum, N and V from the half-adjusted result.
        low = (a & 0x0F) + (v & 0x0F) + carry
        if low > 9:
            low += 6
        if low <= 0x0F:
            t = (low & 0x0F) + (a & 0xF0) + (v & 0xF0)
        else:
            t = (low & 0x0F) + (a & 0xF0) + (v & 0xF0) + 0x10
        overflow = ((a ^ t) & 0x80) != 0 and ((a ^ v) & 0x80) == 0
        negative = t & 0x80
        if (t & 0x1F0) > 0x90:
            t += 0x60
        self.p = (self.p & ~(FLAG_N | FLAG_V | FLAG_Z | FLAG_C)) | negative \
            | (FLAG_V if overflow else 0) | (0 if binary & 0xFF else FLAG_Z) \
            | (FLAG_C if (t & 0xFF0) > 0xF0 else 0)
        self.a = t & 0xFF

    def _sbc(self, v: int) -> None:
        a = self.a
        p = self.p
        borrow = 1 - (p & FLAG_C)
        binary = a - v - borrow
        result = binary & 0xFF
        # Flags come from the binary difference in both modes (64doc).
        p = (p & _KEEP_ALL_BUT_NVZC) | (result & FLAG_N) | (0 if result else FLAG_Z)
        if binary >= 0:
            p |= FLAG_C
        if (a ^ v) & (a ^ binary) & 0x80:
            p |= FLAG_V
        self.p = p
        if not (p & FLAG_D and self.has_decimal):
            self.a = result
            return
        # NMOS decimal SBC (64doc): flags as in binary, the accumulator adjusted per nybble.
        low = (a & 0x0F) - (v & 0x0F) - borrow
        high = (a >> 4) - (v >> 4)
        if low & 0x10:
            low -= 6
            high -= 1
        if high & 0x10:
            high -= 6
        self.a = ((high << 4) | (low & 0x0F)) & 0xFF

    def _arr(self, imm: int) -> None:
        t = self.a & imm
        carry_in = self.p & FLAG_C
        result = (t >> 1) | (carry_in << 7)
        if not self._decimal_on():
            self.a = self._nz(result)
            bit6 = (result >> 6) & 1
            bit5 = (result >> 5) & 1
            self.p = (self.p & ~(FLAG_C | FLAG_V)) | (FLAG_C if bit6 else 0) | (FLAG_V if bit6 ^ bit5 else 0)
            return
        # No More Secrets, ARR in decimal mode: N from the carry in, Z and V from the binary result,
        # then a BCD fix-up of each nybble of the AND result that also decides the carry.
        self.p = (self.p & ~(FLAG_N | FLAG_Z | FLAG_V | FLAG_C)) | (FLAG_N if carry_in else 0) \
            | (0 if result else FLAG_Z) | (FLAG_V if (t ^ result) & 0x40 else 0)
        if (t & 0x0F) + (t & 0x01) > 5:
            result = (result & 0xF0) | ((result + 6) & 0x0F)
        if (t & 0xF0) + (t & 0x10) > 0x50:
            result = (result + 0x60) & 0xFF
            self.p |= FLAG_C
        self.a = result

    # Documented ADC/SBC go through the same helpers so the 2A03 variant drops decimal in one place.
    def opADC(self, x):
        self._adc(self.ByteAt(x()))

    def opSBC(self, x):
        self._sbc(self.ByteAt(x()))

    # ---- undocumented operations -------------------------------------------------------------

    def _rmw_then(self, x, modify, then) -> None:
        addr = x()
        old = self.ByteAt(addr)
        new = modify(old)
        self._write_back(addr, old, new)
        then(new)

    def opSLO(self, x):
        self._rmw_then(x, self._asl, lambda v: setattr(self, "a", self._nz(self.a | v)))

    def opRLA(self, x):
        self._rmw_then(x, self._rol, lambda v: setattr(self, "a", self._nz(self.a & v)))

    def opSRE(self, x):
        self._rmw_then(x, self._lsr, lambda v: setattr(self, "a", self._nz(self.a ^ v)))

    def opRRA(self, x):
        self._rmw_then(x, self._ror, self._adc)

    def opDCP(self, x):
        self._rmw_then(x, lambda v: (v - 1) & 0xFF, lambda v: self._compare(self.a, v))

    def opISC(self, x):
        self._rmw_then(x, lambda v: (v + 1) & 0xFF, self._sbc)

    def opLAX(self, x):
        self.a = self.x = self._nz(self.ByteAt(x()))

    def opSAX(self, x):
        self.WriteByte(x(), self.a & self.x)

    def opNOPRead(self, x):
        self.ByteAt(x())  # the read happens on the bus (it can clear a latch)

    def halt_on(self, kind: str) -> None:
        # Called while executing the opcode byte, before any operand is consumed: PC is one past it.
        raise CpuHalt(kind, self.current_op, (self.pc - 1) & ADDRESS_MASK)


def _register_undocumented(cls) -> None:
    """Fill the undocumented opcodes into cls's tables from their rows in retro.cpu.opcodes."""
    ins = cls.instruction

    def op(opcode, row, body, length):
        def handler(self):
            body(self)
            self.pc += length - 1
        handler.__name__ = f"inst_0x{opcode:02x}"
        ins(name=row.mnemonic, mode=row.mode, cycles=row.cycles, extracycles=int(row.page_penalty))(handler)

    modes = {
        "zpg": lambda s: s.ZeroPageAddr,
        "zpx": lambda s: s.ZeroPageXAddr,
        "zpy": lambda s: s.ZeroPageYAddr,
        "abs": lambda s: s.AbsoluteAddr,
        "abx": lambda s: s.AbsoluteXAddr,
        "aby": lambda s: s.AbsoluteYAddr,
        "inx": lambda s: s.IndirectXAddr,
        "iny": lambda s: s.IndirectYAddr,
        "imm": lambda s: s.ProgramCounter,
    }

    def with_mode(opcode, row, method):
        address_of = modes[row.mode]
        op(opcode, row, lambda s: getattr(s, method)(address_of(s)), MODE_LENGTH[row.mode])

    def anc(s, v):
        s.a = s._nz(s.a & v)
        s.p = (s.p & ~FLAG_C) | (FLAG_C if s.a & 0x80 else 0)

    def sbx(s, v):
        diff = (s.a & s.x) - v
        s.p = (s.p & ~FLAG_C) | (FLAG_C if diff >= 0 else 0)
        s.x = s._nz(diff & 0xFF)

    immediates = {"ANC": anc, "ALR": lambda s, v: setattr(s, "a", s._lsr(s.a & v)), "ARR": lambda s, v: s._arr(v),
                  "SBX": sbx, "SBC": lambda s, v: s._sbc(v)}
    for opcode, row in opcodes_of(STABLE).items():
        name = row.mnemonic
        if name in UNDOCUMENTED_RMW or name in ("LAX", "SAX"):
            with_mode(opcode, row, f"op{name}")
        elif name == "NOP" and row.mode in ("imp", "imm"):
            op(opcode, row, lambda s: None, MODE_LENGTH[row.mode])
        elif name == "NOP":
            with_mode(opcode, row, "opNOPRead")  # these really read memory
        else:
            body = immediates[name]
            op(opcode, row, lambda s, body=body: body(s, s.ByteAt(s.pc)), MODE_LENGTH[row.mode])
    for opcode, row in opcodes_of(JAM).items():
        op(opcode, row, lambda s: s.halt_on("JAM"), 1)
    for opcode, row in opcodes_of(UNSTABLE).items():
        op(opcode, row, lambda s, n=row.mnemonic: s.halt_on(f"unstable opcode {n}"), 1)
    cls.RMW_OPCODES = frozenset(opcode for opcode, row in OPCODE_TABLE.items()
                                if row.mode != "acc" and row.mnemonic in RMW_MNEMONICS)


_register_undocumented(MPU6510)
MPU6510.cycletime[0xCE] = 6  # DEC abs: py65 1.2.0 charges 3; the datasheet says 6.


# ---- the commonest instructions in one frame each --------------------------------------------------
# py65 runs an instruction as three or four calls (instruction, operation, addressing mode, bus); these,
# the opcodes that make most of the built-in routines' paths, do the same work with fewer. Same results,
# cycles and bus accesses (data through ByteAt/WriteByte, opcode and operands from RAM): the CPU test
# vectors run every opcode.

def _set_nz(self, value: int) -> int:
    self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
    return value


def _fused_handlers() -> dict[int, object]:
    def sta_zpg(self):
        self.WriteByte(self.memory[self.pc], self.a)
        self.pc += 1

    def lda_zpg(self):
        self.a = value = self.ByteAt(self.memory[self.pc])
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def lda_imm(self):
        self.a = value = self.ByteAt(self.pc)
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def lda_indexed(by_x: bool):  # LDA abs,X and abs,Y
        def handler(self):
            memory, pc = self.memory, self.pc
            base = memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8
            self.a = value = self.ByteAt(self._indexed(base, self.x if by_x else self.y))
            self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
            self.pc = pc + 2
        return handler

    def lda_iny(self):
        self.a = value = self.ByteAt(self.IndirectYAddr())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def ora_zpg(self):
        self.a = value = self.a | self.ByteAt(self.memory[self.pc])
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def compare(register: str, zero_page: bool):  # CMP, CPX, CPY: immediate or zero page
        def handler(self):
            pc = self.pc
            diff = getattr(self, register) - self.ByteAt(self.memory[pc] if zero_page else pc)
            self.p = (self.p & _KEEP_ALL_BUT_NZC) | (diff & FLAG_N) | (FLAG_Z if diff == 0 else 0) \
                | (FLAG_C if diff >= 0 else 0)
            self.pc = pc + 1
        return handler

    def adc_zpg(self):
        self._adc(self.ByteAt(self.memory[self.pc]))
        self.pc += 1

    def sbc_zpg(self):
        self._sbc(self.ByteAt(self.memory[self.pc]))
        self.pc += 1

    def tax(self):
        self.x = _set_nz(self, self.a)

    def tay(self):
        self.y = _set_nz(self, self.a)

    def txa(self):
        self.a = _set_nz(self, self.x)

    def tya(self):
        self.a = _set_nz(self, self.y)

    def iny(self):
        self.y = _set_nz(self, (self.y + 1) & 0xFF)

    def clc(self):
        self.p &= ~FLAG_C

    def sec(self):
        self.p |= FLAG_C

    def branch(flag: int, when_set: bool):
        if when_set:
            def handler(self):
                if self.p & flag:
                    self.BranchRelAddr()
                else:
                    self.pc += 1
        else:
            def handler(self):
                if self.p & flag:
                    self.pc += 1
                else:
                    self.BranchRelAddr()
        return handler

    def sta_abs(self):
        memory, pc = self.memory, self.pc
        self.WriteByte(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8, self.a)
        self.pc += 2

    def stx_zpg(self):
        self.WriteByte(self.memory[self.pc], self.x)
        self.pc += 1

    def sty_zpg(self):
        self.WriteByte(self.memory[self.pc], self.y)
        self.pc += 1

    def lda_abs(self):
        memory, pc = self.memory, self.pc
        self.a = value = self.ByteAt(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8)
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 2

    def load(register: str, zero_page: bool):  # LDX, LDY: immediate or zero page
        def handler(self):
            pc = self.pc
            value = self.ByteAt(self.memory[pc] if zero_page else pc)
            setattr(self, register, value)
            self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
            self.pc = pc + 1
        return handler

    def and_imm(self):
        self.a = value = self.a & self.ByteAt(self.pc)
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def ora_imm(self):
        self.a = value = self.a | self.ByteAt(self.pc)
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def eor_imm(self):
        self.a = value = self.a ^ self.ByteAt(self.pc)
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def and_iny(self):
        self.a = value = self.a & self.ByteAt(self.IndirectYAddr())
        self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
        self.pc += 1

    def adc_imm(self):
        self._adc(self.ByteAt(self.pc))
        self.pc += 1

    def sbc_imm(self):
        self._sbc(self.ByteAt(self.pc))
        self.pc += 1

    def sbc_aby(self):
        memory, pc = self.memory, self.pc
        self._sbc(self.ByteAt(self._indexed(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8, self.y)))
        self.pc += 2

    def adc_aby(self):
        memory, pc = self.memory, self.pc
        self._adc(self.ByteAt(self._indexed(memory[pc] | memory[(pc + 1) & ADDRESS_MASK] << 8, self.y)))
        self.pc += 2

    def lsr_acc(self):
        a = self.a
        self.a = value = a >> 1
        self.p = (self.p & _KEEP_ALL_BUT_NZC) | (a & FLAG_C) | (0 if value else FLAG_Z)  # (N: bit 7 is 0)

    def asl_acc(self):
        a = self.a
        self.a = value = (a << 1) & 0xFF
        self.p = (self.p & _KEEP_ALL_BUT_NZC) | (a >> 7) | (value & FLAG_N if value else FLAG_Z)

    def step_zpg(delta: int):  # INC zpg, DEC zpg: read, flags, then the RMW double write
        def handler(self):
            address = self.memory[self.pc]
            old = self.ByteAt(address)
            value = (old + delta) & 0xFF
            self.p = (self.p & _KEEP_ALL_BUT_NZ) | (value & FLAG_N if value else FLAG_Z)
            self._write_back(address, old, value)
            self.pc += 1
        return handler

    def inx(self):
        self.x = _set_nz(self, (self.x + 1) & 0xFF)

    def dex(self):
        self.x = _set_nz(self, (self.x - 1) & 0xFF)

    def dey(self):
        self.y = _set_nz(self, (self.y - 1) & 0xFF)

    handlers = {0x85: sta_zpg, 0xA5: lda_zpg, 0xA9: lda_imm, 0xBD: lda_indexed(True), 0xB1: lda_iny, 0x05: ora_zpg,
                0xC5: compare("a", True), 0xC4: compare("y", True), 0xE4: compare("x", True), 0x65: adc_zpg,
                0xE5: sbc_zpg, 0xAA: tax, 0xA8: tay, 0x8A: txa, 0x98: tya, 0xC8: iny, 0x18: clc, 0x38: sec,
                0x8D: sta_abs, 0x86: stx_zpg, 0x84: sty_zpg, 0xAD: lda_abs, 0xB9: lda_indexed(False),
                0xA2: load("x", False), 0xA0: load("y", False),
                0xA6: load("x", True), 0xA4: load("y", True),
                0x29: and_imm, 0x09: ora_imm, 0x49: eor_imm, 0x31: and_iny,
                0xC9: compare("a", False), 0xE0: compare("x", False), 0xC0: compare("y", False),
                0x69: adc_imm, 0xE9: sbc_imm, 0xF9: sbc_aby, 0x79: adc_aby, 0x4A: lsr_acc, 0x0A: asl_acc,
                0xE6: step_zpg(1), 0xC6: step_zpg(-1), 0xE8: inx, 0xCA: dex, 0x88: dey}
    for opcode, flag, when_set in ((0x10, FLAG_N, False), (0x30, FLAG_N, True), (0x50, FLAG_V, False),
                                   (0x70, FLAG_V, True), (0x90, FLAG_C, False), (0xB0, FLAG_C, True),
                                   (0xD0, FLAG_Z, False), (0xF0, FLAG_Z, True)):
        handlers[opcode] = branch(flag, when_set)
    return handlers


for _opcode, _handler in _fused_handlers().items():
    _handler.__name__ = f"inst_0x{_opcode:02x}"
    MPU6510.instruct[_opcode] = _handler

_py65_brk = MPU6510.instruct[OPCODE_BRK]


def _brk(self):
    if self.stop_on_brk:
        self.halt_on("BRK")
    _py65_brk(self)


MPU6510.instruct[OPCODE_BRK] = _brk


class MPU2A03(MPU6510):
    """The NES CPU (Ricoh 2A03/2A07): a 6502 whose decimal mode was removed; D is still a flag."""

    instruct, cycletime, extracycles, disassemble = _copy_tables(MPU6510)
    has_decimal = False
