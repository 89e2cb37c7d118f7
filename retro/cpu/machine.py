"""Machine: a CPU on a bus, with programs loaded, that calls routines and reports exactly what they did.

`Machine.call(entry, a=, x=, y=, memory=...)` runs a routine as if called by JSR and stops at the RTS
that returns from it. The reported cycles run from the routine's first instruction through that RTS;
the caller's JSR (6 cycles) is not included. The machine clock (`Machine.cycle`) keeps running
across calls, so devices see one continuous timeline.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from retro.cpu.bus import MEMORY_SIZE, Bus, Device
from retro.cpu.disassembly import instruction_text
from retro.cpu.mpu import (
    FLAG_B,
    FLAG_C,
    FLAG_D,
    FLAG_I,
    FLAG_N,
    FLAG_U,
    FLAG_V,
    FLAG_Z,
    INTERRUPT_CYCLES,
    OPCODE_BRK,
    CpuHalt,
)
from retro.cpu.timing import model_cycles, step_model
from retro.cpu.traps import TRAP_OPCODE
from retro.cpu.variants import VARIANTS
from retro.errors import InputError, RunError
from retro.numbers import parse_int
from retro.program import Program, ambiguity_message

DEFAULT_BUDGET = 5_000_000  # cycles; about five seconds of C64 time, a few seconds on the host
MAX_BUDGET = 100_000_000  # cycles; about 100 s of C64 time, a minute or two on the host
MAX_TRACE = 200_000  # instructions a trace keeps (about 30 MB); a longer traced run is stopped
RETURN_TRAP = 0x0000  # the routine "returns" here: RTS to $0000 with the stack back where it started
CALL_STACK_TOP = 0xFF
ENTRY_S = CALL_STACK_TOP - 2  # S on a routine's entry by default: an empty stack after the caller's JSR
STACK_BASE = 0x100  # the 6502's stack is page 1
DEFAULT_FLAGS = FLAG_U | FLAG_I
RECENT_SHOWN = 8  # instructions listed in a failure message
NO_ADDRESS = -1  # a stop address the PC never equals
ANY_STACK = -1  # stop at the address whatever the stack pointer
JSR_CYCLES = 6  # the caller's JSR, excluded from every reported count
OPCODE_JSR = 0x20
ENTRIES = ("jsr", "irq", "nmi")  # how a routine is entered: called by JSR, or as an interrupt handler
LOADS = frozenset({"LDA", "LDX", "LDY", "LAX"})
STORES = frozenset({"STA", "STX", "STY", "SAX", "SHA", "SHX", "SHY", "TAS", "STZ"})


@dataclass(frozen=True)
class TraceEntry:
    address: int
    opcode: int
    mnemonic: str
    mode: str
    cycles: int
    page_crossed: bool
    branch_taken: bool
    stolen: int = 0  # cycles of `cycles` the CPU stood still (BA low: Bad Line, sprite DMA)
    operand: int | None = None  # the memory address the instruction used (None: none)
    read: int | None = None  # the value it read there (loads: what reached the register)


@dataclass
class CallResult:
    a: int
    x: int
    y: int
    s: int
    p: int
    cycles: int
    instructions: int
    trace: list[TraceEntry] | None = None
    flags: dict[str, bool] = field(default_factory=dict)
    stolen: int = 0  # of `cycles`, those the CPU stood still (only with a chip driving BA)


def push_return_trap(memory, s: int = ENTRY_S) -> int:
    """Put on the stack what a JSR from RETURN_TRAP pushes (its return address minus one, high byte
    first) so that S is `s` after it, and return S: how every call is entered, on Machine and the
    batched core. The call has returned when the PC is RETURN_TRAP and S is `return_s(s)`."""
    back = (RETURN_TRAP - 1) & 0xFFFF
    memory[STACK_BASE | return_s(s)], memory[STACK_BASE | ((s + 1) & 0xFF)] = back >> 8, back & 0xFF
    return s


def return_s(s):
    """S after the RTS of a routine entered with S = s (an int, or a numpy array of lanes): the stack
    top before the call's JSR, where an interrupt handler's RTI (or an exit) ends the call too."""
    return (s + 2) & 0xFF


def push_interrupt_frame(memory, p: int, top: int = CALL_STACK_TOP) -> int:
    """Put on the stack, from S = top, what the CPU's interrupt sequence pushes when it interrupts
    RETURN_TRAP (the address, high byte first, then P with B clear) and return S after it: how an IRQ
    or NMI handler is entered (its RTI then returns to RETURN_TRAP with S back at top)."""
    base = STACK_BASE | top
    memory[base], memory[base - 1], memory[base - 2] = RETURN_TRAP >> 8, RETURN_TRAP & 0xFF, (p | FLAG_U) & ~FLAG_B
    return top - 3


def interrupt_entry_flags(mpu_class, p: int) -> int:
    """P inside a handler the CPU has just entered: I set (and, on the 65C02, D clear)."""
    return (p | FLAG_I) & ~mpu_class.interrupt_clears


def _status(p: int) -> int:
    """P as the register holds it: bit 5 reads as 1, and bit 4 (B) exists only in pushed copies."""
    return (p | FLAG_U) & ~FLAG_B


def _flags(p: int) -> dict[str, bool]:
    return {name: bool(p & bit) for name, bit in
            (("N", FLAG_N), ("V", FLAG_V), ("D", FLAG_D), ("I", FLAG_I), ("Z", FLAG_Z), ("C", FLAG_C))}


class Machine:
    def __init__(self, variant: str = "6510") -> None:
        if variant not in VARIANTS:
            raise InputError(f"unknown CPU variant {variant!r} (known: {', '.join(VARIANTS)})")
        self.variant = variant
        self.bus = Bus()
        self.mpu = VARIANTS[variant](memory=self.bus.memory, page_devices=self.bus.page_devices)
        self.mpu.stop_on_brk = True
        self.stack_top = CALL_STACK_TOP  # S before a call's JSR (the entry-state runs of a check vary it)
        self.stop_s = CALL_STACK_TOP  # S at which the call running now ends
        self.symbols: dict[str, int] = {}
        self.ambiguous: dict[str, tuple[str, ...]] = {}
        self.trap_names: dict[int, str] = {}  # a trap's address (retro.cpu.traps) -> what listings call it
        self.step_model = step_model(variant)  # the timing model, as the recording loop reads it

    @property
    def entry_s(self) -> int:
        """S at a called routine's first instruction when the caller does not say: an empty stack
        from `stack_top` after the JSR."""
        return (self.stack_top - 2) & 0xFF

    # ---- set-up ----------------------------------------------------------------------------

    @property
    def cycle(self) -> int:
        """The machine clock: CPU cycles since power-on."""
        return self.mpu.processorCycles

    @property
    def memory(self) -> list[int]:
        return self.bus.memory

    def attach(self, device: Device, start: int, end: int) -> Device:
        drives_lines = getattr(device, "drives_cpu_lines", False)
        if drives_lines and self.mpu.lines not in (None, device):
            raise InputError("a second chip driving the CPU's BA/IRQ/NMI lines; a machine has one")
        self.bus.map(device, start, end)
        if drives_lines:
            self.mpu.lines = device  # from now on the timed run loop (stalls, interrupts) is used
        return device

    def load(self, program: Program) -> Program:
        self.bus.load(program.origin, program.code)
        self.symbols.update(program.symbols)
        self.ambiguous.update(program.ambiguous)
        return program

    def resolve(self, target: str | int, field: str = "address") -> int:
        """A label of a loaded program, or a number in any accepted notation."""
        if isinstance(target, int):
            return parse_int(target, field=field, lo=0, hi=0xFFFF)
        text = str(target).strip()
        if text in self.ambiguous and text not in self.symbols:
            raise InputError(f"{field}: {ambiguity_message(text, self.ambiguous[text])}")
        if text in self.symbols:
            return self.symbols[text]
        if text[:1].isalpha() or text[:1] == "_":
            if not (text.lower().startswith("0x") or text.lower().startswith("0b")):
                raise InputError(f"{field}: unknown label {text!r}")
        return parse_int(text, field=field, lo=0, hi=0xFFFF)

    def poke(self, target: str | int, values: int | bytes | list[int]) -> None:
        data = [values] if isinstance(values, int) else list(values)
        address = self._span(target, len(data))
        for offset, value in enumerate(data):
            if not 0 <= value <= 0xFF:
                raise InputError(f"value {value} for {target} is not a byte (0-255)")
            self.bus.poke(address + offset, value)

    def peek(self, target: str | int, count: int = 1) -> list[int]:
        address = self._span(target, count)
        return [self.bus.peek(address + i) for i in range(count)]

    def _span(self, target: str | int, count: int) -> int:
        """The address of target, checking that count bytes from it stay below $10000 (no wrap to $0000)."""
        address = self.resolve(target)
        if address + count > MEMORY_SIZE:
            raise InputError(f"{target}: {count} bytes from ${address:04X} run past $FFFF")
        return address

    # ---- running ---------------------------------------------------------------------------

    def call(self, entry: str | int, *, a: int = 0, x: int = 0, y: int = 0, p: int = DEFAULT_FLAGS,
             memory: dict | None = None, budget: int = DEFAULT_BUDGET, trace: bool = False,
             enter: str = "jsr", s: int | None = None, observer=None) -> CallResult:
        """Run the routine at entry as if called by JSR; stop at its RTS (`enter` "irq" or "nmi": as
        the CPU enters an interrupt handler, the 7 cycles of its sequence counted; stop at its RTI).
        `s`: S at the routine's first instruction (default: `stack_top` - 2, an empty stack after the JSR).
        `observer` (without `trace`) is told of every step as in `MPU6510.run` (a profile).

        Fails (RunError) on BRK, JAM or an unstable opcode, and when the routine needs more than
        `budget` cycles (a runaway routine is stopped as soon as it has used them).
        """
        address = self.resolve(entry, "entry")
        s = self.entry_s if s is None else s
        for name, value in (("a", a), ("x", x), ("y", y), ("p", p), ("s", s)):
            if not 0 <= value <= 0xFF:
                raise InputError(f"{name}: {value} is not a byte (0-255)")
        if not 1 <= budget <= MAX_BUDGET:
            raise InputError(f"budget: {budget} is not a number of cycles in 1..{MAX_BUDGET:,}")
        if enter not in ENTRIES:
            raise InputError(f"enter: {enter!r} is not one of {', '.join(ENTRIES)}")
        for target, values in (memory or {}).items():
            self.poke(target, values)
        entries: list[TraceEntry] | None = [] if trace else None
        start = self._enter(address, a, x, y, p, enter, s)
        stolen_before = self.mpu.stolen
        if entries is not None and observer is not None:
            raise ValueError("Machine.call: a trace or an observer, not both")
        count = self._execute(RETURN_TRAP, return_s(s), start + budget,
                              observer if entries is None else _Tracer(self, entries))
        cycles = self._returned(start, budget, count, return_s(s))
        mpu = self.mpu
        status = _status(mpu.p)
        return CallResult(a=mpu.a, x=mpu.x, y=mpu.y, s=mpu.sp, p=status, cycles=cycles,
                          instructions=count, trace=entries, flags=_flags(status),
                          stolen=mpu.stolen - stolen_before)

    def _enter(self, address: int, a: int, x: int, y: int, p: int, enter: str, s: int) -> int:
        """Set registers and the stack as a JSR from the return trap would (or, `enter` "irq"/"nmi",
        as the interrupt sequence would, interrupting the return trap); return the start cycle."""
        mpu = self.mpu
        mpu.a, mpu.x, mpu.y, mpu.p = a, x, y, _status(p)
        mpu.pc = address
        mpu.pending_interrupt = None  # a poll before the call does not carry into it
        self.stop_s = return_s(s)  # where this call ends (a world's exit sets S to it)
        if enter == "jsr":
            mpu.sp = push_return_trap(mpu.memory, s)
            return mpu.processorCycles
        mpu.sp = push_interrupt_frame(mpu.memory, mpu.p, return_s(s))
        mpu.p = interrupt_entry_flags(type(mpu), mpu.p)
        mpu.processorCycles += INTERRUPT_CYCLES  # the sequence's cycles (no stall is modelled in them)
        return mpu.processorCycles - INTERRUPT_CYCLES

    def _returned(self, start: int, budget: int, count: int, stop_s: int = CALL_STACK_TOP) -> int:
        """The routine's cycles, or a RunError if it did not return within the budget."""
        mpu = self.mpu
        if mpu.pc != RETURN_TRAP or mpu.sp != stop_s:
            self._over_budget(budget, count)
        cycles = mpu.processorCycles - start
        if cycles > budget:  # returned, but its last instruction ran past the budget
            raise RunError(f"cycle budget of {budget} cycles exceeded: the routine returned after {cycles} cycles")
        return cycles

    def call_fast(self, address: int, writes=(), *, a: int = 0, x: int = 0, y: int = 0, p: int = DEFAULT_FLAGS,
                  budget: int = DEFAULT_BUDGET, record: list | None = None,
                  pointer_pcs: frozenset[int] = frozenset(), enter: str = "jsr",
                  s: int | None = None, timed: bool = False) -> tuple[int, int, int, int, int]:
        """`call` for sweeps of many thousands of calls: the same run without its conveniences.

        `address` is the entry as a number, `writes` are raw (address, byte) pairs stored into RAM,
        register values are trusted. Returns (cycles, a, x, y, p) with p as `call` reports it.
        With `record` (a list), each executed instruction appends (pc, x, y, p, pointer, a) as they were
        before it ran; pointer is the zero-page word its operand names when its PC is in
        `pointer_pcs` (for (indirect),Y instructions), else 0. `timed`: the independent timing model
        (retro.cpu.timing) also counts the executed path, into `last_modelled`. Failures are RunErrors
        as in `call`.
        """
        memory = self.bus.memory
        for target, value in writes:
            memory[target] = value
        s = self.entry_s if s is None else s
        start = self._enter(address, a, x, y, p, enter, s)
        stop_s = return_s(s)
        if (record is not None or timed) and self.mpu.lines is None:  # the loop that records and times itself
            count = self._execute(RETURN_TRAP, stop_s, start + budget, recorded=(record, pointer_pcs))
            self.last_modelled = self.mpu.modelled if timed else None
        else:
            if timed and record is None:
                record = []
            observer = None if record is None else _Recorder(record, pointer_pcs)
            count = self._execute(RETURN_TRAP, stop_s, start + budget, observer)
            self.last_modelled = model_cycles(memory.__getitem__, record, self.variant) if timed else None
        cycles = self._returned(start, budget, count, stop_s)
        mpu = self.mpu
        return cycles, mpu.a, mpu.x, mpu.y, _status(mpu.p)

    last_modelled: int | None = None  # the timing model's cycles of the last `call_fast(timed=True)`

    def run(self, entry: str | int, *, until: str | int | None = None, cycles: int = DEFAULT_BUDGET) -> int:
        """Run from entry for a number of cycles, or until the PC reaches `until` (error if it never does).

        Returns the number of instructions executed. For programs that never return (main loops).
        """
        mpu = self.mpu
        mpu.pc = self.resolve(entry, "entry")
        stop = self.resolve(until, "until") if until is not None else NO_ADDRESS
        count = self._execute(stop, ANY_STACK, mpu.processorCycles + cycles, None)
        if until is not None and mpu.pc != stop:
            self._over_budget(cycles, count)
        return count

    def run_on(self, cycles: int, *, until: int | None = None, observer=None) -> int:
        """Go on from the current state (PC, registers, a pending interrupt) for `cycles` cycles or
        until the PC reaches `until`; returns the instructions executed. For whole programs run in
        slices (`retro run` of a cartridge); `observer` as in `MPU6510.run`."""
        stop = NO_ADDRESS if until is None else until
        return self._execute(stop, ANY_STACK, self.mpu.processorCycles + cycles, observer)

    def _execute(self, stop_pc: int, stop_sp: int, limit: int, observer=None,
                 recorded: tuple[list | None, frozenset[int]] | None = None) -> int:
        """Run to stop_pc (and stop_sp) or the limit (the MPU's run loop; `recorded`: (record,
        pointer_pcs) for its recording loop, `run_recorded`, no chip on the control lines); a CpuHalt
        becomes a RunError saying where."""
        mpu = self.mpu
        try:
            if recorded is not None:
                return mpu.run_recorded(stop_pc, stop_sp, limit, *recorded, self.step_model)
            return mpu.run(stop_pc, stop_sp, limit, observer)
        except CpuHalt as halt:
            raise RunError(f"{self._called_nowhere(halt) or halt}; last instructions: "
                           f"{self._describe_recent(mpu.executed)}") from None

    def _called_nowhere(self, halt: CpuHalt) -> str | None:
        """A BRK met right after a JSR to its address: a call into memory that holds no code."""
        recent = self.mpu.recent_addresses(self.mpu.executed)
        if halt.opcode != OPCODE_BRK or len(recent) < 2:
            return None
        caller = recent[-2]
        memory = self.mpu.memory
        if memory[caller] != OPCODE_JSR or (memory[(caller + 1) & 0xFFFF] | memory[(caller + 2) & 0xFFFF] << 8) != halt.address:
            return None
        return (f"JSR ${halt.address:04X} at ${caller:04X} calls an address where no code is (a BRK there): "
                f"give the program that code, or say what the call does with a mock ([mocks] NAME = "
                f"{{ at = \"${halt.address:04X}\", cycles = N }}, docs/specs.md)")

    def _operand_address(self, pc: int, mode: str) -> int | None:
        """The effective address of the instruction at pc, from the registers before it runs."""
        memory = self.mpu.memory
        mpu = self.mpu
        lo = memory[(pc + 1) & 0xFFFF]
        word = lo | memory[(pc + 2) & 0xFFFF] << 8
        if mode == "zpg":
            return lo
        if mode in ("zpx", "zpy"):
            return (lo + (mpu.x if mode == "zpx" else mpu.y)) & 0xFF
        if mode == "abs":
            return word
        if mode in ("abx", "aby"):
            return (word + (mpu.x if mode == "abx" else mpu.y)) & 0xFFFF
        if mode == "inx":
            pointer = (lo + mpu.x) & 0xFF
            return memory[pointer] | memory[(pointer + 1) & 0xFF] << 8
        if mode == "iny":
            return ((memory[lo] | memory[(lo + 1) & 0xFF] << 8) + mpu.y) & 0xFFFF
        if mode in ("zpi", "zpr"):  # 65C02: (zp), and the zero-page byte BBR/BBS test
            return memory[lo] | memory[(lo + 1) & 0xFF] << 8 if mode == "zpi" else lo
        return None

    def _over_budget(self, budget: int, count: int) -> None:
        raise RunError(f"cycle budget of {budget} cycles used up at PC ${self.mpu.pc:04X} after {count} "
                       f"instructions; last instructions: {self._describe_recent(count)}")

    def _describe_recent(self, count: int) -> str:
        shown = self.mpu.recent_addresses(count)[-RECENT_SHOWN:]
        return ", ".join(f"${a:04X} {self.disassemble_at(a)}" for a in shown)

    def disassemble_at(self, address: int) -> str:
        memory = self.mpu.memory
        if memory[address] == TRAP_OPCODE and address in self.trap_names:
            return self.trap_names[address]
        mnemonic, mode = self.mpu.disassemble[memory[address]]
        return instruction_text(mnemonic, mode, address, memory[(address + 1) & 0xFFFF], memory[(address + 2) & 0xFFFF])


class _Recorder:
    """Observer of the run loop: each instruction's (pc, x, y, p, pointer, a) before it runs, for the
    timing model (pointer: the zero-page word of an (indirect),Y instruction in `pointer_pcs`, else 0)
    and the spec's stated facts (retro.routines.facts)."""

    def __init__(self, record: list, pointer_pcs: frozenset[int]) -> None:
        self.append = record.append
        self.pointer_pcs = pointer_pcs

    def before(self, mpu) -> None:
        if mpu.pending_interrupt is not None:
            return  # the interrupt sequence is not an instruction
        pc = mpu.pc
        if pc in self.pointer_pcs:
            memory = mpu.memory
            zp = memory[(pc + 1) & 0xFFFF]
            self.append((pc, mpu.x, mpu.y, _status(mpu.p), memory[zp] | memory[(zp + 1) & 0xFF] << 8, mpu.a))
        else:
            self.append((pc, mpu.x, mpu.y, _status(mpu.p), 0, mpu.a))

    def after(self, mpu) -> None:
        pass


class _Tracer:
    """Observer of the run loop: a TraceEntry per step (an instruction, or an interrupt sequence at
    the address it interrupts), at most MAX_TRACE of them."""

    def __init__(self, machine: Machine, entries: list[TraceEntry]) -> None:
        self.machine = machine
        self.entries = entries

    def before(self, mpu) -> None:
        if len(self.entries) >= MAX_TRACE:
            raise RunError(f"the trace is longer than {MAX_TRACE:,} instructions (at PC ${mpu.pc:04X}): "
                           "give a smaller budget, or run without the trace")
        self.address = address = mpu.pc
        self.interrupt = mpu.pending_interrupt if mpu.lines is not None else None
        self.cycles_before = mpu.processorCycles
        if self.interrupt is not None:
            return
        self.opcode = opcode = mpu.memory[address]
        self.mnemonic, self.mode = mnemonic, mode = mpu.disassemble[opcode]
        operand = self.machine._operand_address(address, mode) if mnemonic not in ("JMP", "JSR") else None
        self.operand = operand
        self.reads = reads = operand is not None and mnemonic not in STORES
        self.before_value = self.machine.bus.peek(operand) if reads and mnemonic not in LOADS else None

    def after(self, mpu) -> None:
        stolen = 0 if mpu.lines is None else mpu.last_stolen
        cycles = mpu.processorCycles - self.cycles_before
        if self.interrupt is not None:  # the interrupt sequence: its own line, at the address it interrupts
            self.entries.append(TraceEntry(address=self.address, opcode=-1, mnemonic=self.interrupt, mode="int",
                                           cycles=cycles, page_crossed=False, branch_taken=False, stolen=stolen))
            return
        mnemonic, mode = self.mnemonic, self.mode
        extra = cycles - stolen - mpu.cycletime[self.opcode]
        if mnemonic in ("ADC", "SBC") and mpu.p & FLAG_D:
            extra -= mpu.decimal_extra_cycles  # the 65C02's decimal cycle is no page crossing
        is_branch = mode in ("rel", "zpr")  # zpr: the 65C02's BBR/BBS
        value = self.before_value
        if self.reads and mnemonic in LOADS:  # what the load put in its register is what it read
            value = {"LDA": mpu.a, "LDX": mpu.x, "LDY": mpu.y, "LAX": mpu.a}[mnemonic]
        self.entries.append(TraceEntry(address=self.address, opcode=self.opcode, mnemonic=mnemonic, mode=mode,
                                       cycles=cycles, page_crossed=(extra == 2) if is_branch else extra == 1,
                                       branch_taken=is_branch and extra >= 1, stolen=stolen, operand=self.operand,
                                       read=value))
