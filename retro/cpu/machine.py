"""Machine: a CPU on a bus, with programs loaded, that calls routines and reports exactly what they did.

`Machine.call(entry, a=, x=, y=, memory=...)` runs a routine as if called by JSR and stops at the RTS
that returns from it. The reported cycles run from the routine's first instruction through that RTS;
the caller's JSR (6 cycles) is not included. The machine clock (`Machine.cycle`) keeps running
across calls, so devices see one continuous timeline.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from retro.cpu.bus import Bus, Device
from retro.cpu.mpu import FLAG_I, FLAG_U, VARIANTS, CpuHalt
from retro.errors import InputError, RunError
from retro.numbers import parse_int
from retro.program import Program

DEFAULT_BUDGET = 5_000_000  # cycles; about five seconds of C64 time, a few seconds on the host
RETURN_TRAP = 0x0000  # the routine "returns" here: RTS to $0000 with the stack back where it started
CALL_STACK_TOP = 0xFF
DEFAULT_FLAGS = FLAG_U | FLAG_I
RECENT_INSTRUCTIONS = 16
JSR_CYCLES = 6  # the caller's JSR, excluded from every reported count


@dataclass(frozen=True)
class TraceEntry:
    address: int
    opcode: int
    mnemonic: str
    mode: str
    cycles: int
    page_crossed: bool
    branch_taken: bool


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


def _flags(p: int) -> dict[str, bool]:
    return {name: bool(p & bit) for name, bit in
            (("N", 0x80), ("V", 0x40), ("D", 0x08), ("I", 0x04), ("Z", 0x02), ("C", 0x01))}


class Machine:
    def __init__(self, variant: str = "6510") -> None:
        if variant not in VARIANTS:
            raise InputError(f"unknown CPU variant {variant!r} (known: {', '.join(VARIANTS)})")
        self.variant = variant
        self.bus = Bus()
        self.mpu = VARIANTS[variant](memory=self.bus.memory, page_devices=self.bus.page_devices)
        self.mpu.stop_on_brk = True
        self.symbols: dict[str, int] = {}

    # ---- set-up ----------------------------------------------------------------------------

    @property
    def cycle(self) -> int:
        """The machine clock: CPU cycles since power-on."""
        return self.mpu.processorCycles

    @property
    def memory(self) -> list[int]:
        return self.bus.memory

    def attach(self, device: Device, start: int, end: int) -> Device:
        self.bus.map(device, start, end)
        return device

    def load(self, program: Program) -> Program:
        self.bus.load(program.origin, program.code)
        self.symbols.update(program.symbols)
        return program

    def resolve(self, target: str | int, field: str = "address") -> int:
        """A label of a loaded program, or a number in any accepted notation."""
        if isinstance(target, int):
            return parse_int(target, field=field, lo=0, hi=0xFFFF)
        text = str(target).strip()
        if text in self.symbols:
            return self.symbols[text]
        if text[:1].isalpha() or text[:1] == "_":
            if not (text.lower().startswith("0x") or text.lower().startswith("0b")):
                raise InputError(f"{field}: unknown label {text!r}")
        return parse_int(text, field=field, lo=0, hi=0xFFFF)

    def poke(self, target: str | int, values: int | bytes | list[int]) -> None:
        address = self.resolve(target)
        data = [values] if isinstance(values, int) else list(values)
        for offset, value in enumerate(data):
            if not 0 <= value <= 0xFF:
                raise InputError(f"value {value} for {target} is not a byte (0-255)")
            self.bus.poke((address + offset) & 0xFFFF, value)

    def peek(self, target: str | int, count: int = 1) -> list[int]:
        address = self.resolve(target)
        return [self.bus.peek((address + i) & 0xFFFF) for i in range(count)]

    # ---- running ---------------------------------------------------------------------------

    def call(self, entry: str | int, *, a: int = 0, x: int = 0, y: int = 0, p: int = DEFAULT_FLAGS,
             memory: dict | None = None, budget: int = DEFAULT_BUDGET, trace: bool = False) -> CallResult:
        """Run the routine at entry as if called by JSR; stop at its RTS."""
        address = self.resolve(entry, "entry")
        for name, value in (("a", a), ("x", x), ("y", y), ("p", p)):
            if not 0 <= value <= 0xFF:
                raise InputError(f"{name}: {value} is not a byte (0-255)")
        for target, values in (memory or {}).items():
            self.poke(target, values)
        mpu = self.mpu
        mpu.a, mpu.x, mpu.y, mpu.p = a, x, y, p | FLAG_U
        mpu.sp = CALL_STACK_TOP
        mpu.stPushWord((RETURN_TRAP - 1) & 0xFFFF)
        mpu.pc = address
        start = mpu.processorCycles
        entries: list[TraceEntry] | None = [] if trace else None
        count = self._run_until_return(start + budget, entries)
        return CallResult(a=mpu.a, x=mpu.x, y=mpu.y, s=mpu.sp, p=mpu.p, cycles=mpu.processorCycles - start,
                          instructions=count, trace=entries, flags=_flags(mpu.p))

    def _run_until_return(self, limit: int, entries: list[TraceEntry] | None) -> int:
        mpu = self.mpu
        step = mpu.step
        recent = [0] * RECENT_INSTRUCTIONS
        count = 0
        try:
            if entries is None:
                while mpu.pc != RETURN_TRAP or mpu.sp != CALL_STACK_TOP:
                    recent[count % RECENT_INSTRUCTIONS] = mpu.pc
                    step()
                    count += 1
                    if mpu.processorCycles >= limit:
                        self._over_budget(limit, recent, count)
            else:
                while mpu.pc != RETURN_TRAP or mpu.sp != CALL_STACK_TOP:
                    recent[count % RECENT_INSTRUCTIONS] = mpu.pc
                    entries.append(self._traced_step())
                    count += 1
                    if mpu.processorCycles >= limit:
                        self._over_budget(limit, recent, count)
        except CpuHalt as halt:
            recent[count % RECENT_INSTRUCTIONS] = halt.address
            raise RunError(f"{halt}; last instructions: {self._describe_recent(recent, count + 1)}") from None
        return count

    def _traced_step(self) -> TraceEntry:
        mpu = self.mpu
        address = mpu.pc
        opcode = mpu.memory[address]
        before = mpu.processorCycles
        mpu.step()
        cycles = mpu.processorCycles - before
        mnemonic, mode = mpu.disassemble[opcode]
        extra = cycles - mpu.cycletime[opcode]
        is_branch = mode == "rel"
        return TraceEntry(address=address, opcode=opcode, mnemonic=mnemonic, mode=mode, cycles=cycles,
                          page_crossed=(extra == 2) if is_branch else extra == 1,
                          branch_taken=is_branch and extra >= 1)

    def run(self, entry: str | int, *, until: str | int | None = None, cycles: int = DEFAULT_BUDGET) -> int:
        """Run from entry for a number of cycles, or until the PC reaches `until` (error if it never does).

        Returns the number of instructions executed. For programs that never return (main loops).
        """
        mpu = self.mpu
        mpu.pc = self.resolve(entry, "entry")
        stop = self.resolve(until, "until") if until is not None else None
        limit = mpu.processorCycles + cycles
        step = mpu.step
        recent = [0] * RECENT_INSTRUCTIONS
        count = 0
        try:
            while mpu.processorCycles < limit:
                if mpu.pc == stop:
                    return count
                recent[count % RECENT_INSTRUCTIONS] = mpu.pc
                step()
                count += 1
        except CpuHalt as halt:
            recent[count % RECENT_INSTRUCTIONS] = halt.address
            raise RunError(f"{halt}; last instructions: {self._describe_recent(recent, count + 1)}") from None
        if stop is not None and mpu.pc != stop:
            self._over_budget(limit, recent, count)
        return count

    def _over_budget(self, limit: int, recent: list[int], count: int) -> None:
        raise RunError(f"cycle budget exhausted (clock {self.mpu.processorCycles}, limit {limit}) "
                       f"at PC ${self.mpu.pc:04X} after {count} instructions; "
                       f"last instructions: {self._describe_recent(recent, count)}")

    def _describe_recent(self, recent: list[int], count: int) -> str:
        n = min(count, RECENT_INSTRUCTIONS)
        addresses = [recent[(count - n + i) % RECENT_INSTRUCTIONS] for i in range(n)]
        shown = addresses[-8:]
        return ", ".join(f"${a:04X} {self.disassemble_at(a)}" for a in shown)

    def disassemble_at(self, address: int) -> str:
        memory = self.mpu.memory
        opcode = memory[address]
        mnemonic, mode = self.mpu.disassemble[opcode]
        lo = memory[(address + 1) & 0xFFFF]
        hi = memory[(address + 2) & 0xFFFF]
        word = lo | hi << 8
        operand = {
            "imp": "", "acc": "A" if mnemonic in ("ASL", "LSR", "ROL", "ROR") else "", "imm": f"#${lo:02X}",
            "zpg": f"${lo:02X}", "zpx": f"${lo:02X},X", "zpy": f"${lo:02X},Y",
            "abs": f"${word:04X}", "abx": f"${word:04X},X", "aby": f"${word:04X},Y",
            "ind": f"(${word:04X})", "inx": f"(${lo:02X},X)", "iny": f"(${lo:02X}),Y",
            "rel": f"${(address + 2 + (lo - 256 if lo & 0x80 else lo)) & 0xFFFF:04X}",
        }.get(mode, "")
        return f"{mnemonic} {operand}".strip()
