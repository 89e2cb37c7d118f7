"""A bounded trace of a program run, with registers, memory writes and the beam; and watchpoints.

`Tracer` is an observer of the CPU's run loop (as the profiler is: nothing of it runs without it).
Per step (an instruction, or an interrupt sequence) it notes the machine cycle, the beam position
(C64: frame, raster line, cycle in the line 1-63/65; NES: frame, scanline, dot), the address and
the instruction, the registers and flags after it, the memory it read (the effective address and
the value) and every byte it wrote (stores and read-modify-writes at their effective address,
stack pushes of PHA, PHP, JSR, BRK and interrupt sequences).

The trace is bounded: `limit` entries at most (then the run goes on untraced and the report says
the trace was cut), optionally only within a range of cycles from the start of the run, and only
for instructions whose address is in a range. A trace of a whole program run needs a bound: a
limit, a cycle range or an address range (`TraceBounds.check`).

Watchpoints (`Watch`) fire on reads, writes or execution of an address or range, optionally only
when the byte read or written (or, for execution, A) equals a value: each hit is kept (at most
MAX_HITS) with the beam position and the instruction.
"""

from __future__ import annotations

from dataclasses import dataclass

from retro.cpu.machine import LOADS, STORES
from retro.cpu.mpu import FLAG_B, FLAG_U, RMW_MNEMONICS
from retro.errors import InputError

MAX_TRACE_LIMIT = 1_000_000  # entries a trace may keep (about 300 MB of text at most: bounded)
MAX_HITS = 10_000
STACK = 0x100
FLAG_NAMES = "NV-BDIZC"
PUSHES = {"PHA": 1, "PHP": 1, "JSR": 2, "BRK": 3}
STORED = {"STA": lambda m: m.a, "STX": lambda m: m.x, "STY": lambda m: m.y, "SAX": lambda m: m.a & m.x,
          "STZ": lambda m: 0}
_SHIFTS = {"ASL": lambda v, c: v << 1 & 0xFF, "LSR": lambda v, c: v >> 1, "ROL": lambda v, c: (v << 1 | c) & 0xFF,
           "ROR": lambda v, c: v >> 1 | c << 7, "INC": lambda v, c: (v + 1) & 0xFF, "DEC": lambda v, c: (v - 1) & 0xFF}
# the undocumented read-modify-writes write what ASL, ROL, LSR, ROR, DEC and INC would
RMW_RESULT = {**_SHIFTS, "SLO": _SHIFTS["ASL"], "RLA": _SHIFTS["ROL"], "SRE": _SHIFTS["LSR"], "RRA": _SHIFTS["ROR"],
              "DCP": _SHIFTS["DEC"], "ISC": _SHIFTS["INC"]}
KINDS = {"r": "read", "w": "write", "x": "exec", "rw": "access"}


@dataclass(frozen=True)
class TraceBounds:
    limit: int | None = None
    first_cycle: int | None = None  # cycles from the start of the run
    last_cycle: int | None = None
    low: int = 0  # instruction addresses traced
    high: int = 0xFFFF

    @property
    def bounded(self) -> bool:
        return (self.limit is not None or self.last_cycle is not None or (self.low, self.high) != (0, 0xFFFF))

    def check(self) -> None:
        if not self.bounded:
            raise InputError("--trace: a program run needs a bound: --trace-limit N, --trace-cycles FROM-TO or "
                             "--trace-pc LOW-HIGH")


@dataclass(frozen=True)
class Watch:
    kind: str  # "r", "w", "x" or "rw"
    low: int
    high: int
    value: int | None = None
    text: str = ""

    def matches(self, address: int) -> bool:
        return self.low <= address <= self.high


def parse_watch(text: str, resolve) -> Watch:
    """'KIND:TARGET[-TARGET][=V]' (KIND r, w, x or rw; TARGET a label or address) -> Watch."""
    kind, sep, rest = text.partition(":")
    if not sep or kind not in KINDS or not rest.strip():
        raise InputError(f"--watch {text!r}: expected KIND:ADDR[-ADDR][=VALUE] with KIND r, w, x or rw")
    where, eq, value = rest.partition("=")
    first, dash, last = where.partition("-")
    low = resolve(first.strip(), f"--watch {text}")
    high = resolve(last.strip(), f"--watch {text}") if dash else low
    if high < low:
        raise InputError(f"--watch {text!r}: the range ends before it starts")
    from retro.numbers import parse_int
    byte = parse_int(value, field=f"--watch {text} value", lo=0, hi=0xFF) if eq else None
    return Watch(kind, low, high, byte, text)


def vic_position(vic):
    """C64: machine cycle -> (frame, raster line, cycle in the line 1-63/65)."""
    return vic.beam


def ppu_position(ppu):
    """NES: machine cycle -> (frame, scanline, dot), frames of 341 x 262 dots (no odd-frame skip)."""
    from retro.chips.ppu.clock import dots_at_cycle
    from retro.chips.ppu.constants import DOTS_PER_LINE

    def position(cycle: int) -> tuple[int, int, int]:
        frame, within = divmod(dots_at_cycle(cycle, ppu.origin, ppu.video), ppu.video.dots_per_frame)
        return (frame, *divmod(within, DOTS_PER_LINE))
    return position


def flags_text(p: int) -> str:
    return "".join(name if p >> (7 - i) & 1 else "." for i, name in enumerate(FLAG_NAMES))


class Tracer:
    """The run loop's observer (module docstring). `position(cycle)` gives the beam as (frame, line,
    in-line); `inner` is told after this one (a run's stop conditions or a profiler)."""

    def __init__(self, machine, *, bounds: TraceBounds | None = None, watches: tuple[Watch, ...] = (),
                 position=None, inner=None) -> None:
        self.machine = machine
        self.mpu = machine.mpu
        self.peek = machine.bus.peek
        self.bounds = bounds
        self.watches = watches
        self.position = position
        self.inner = inner
        self.entries: list[dict] = []
        self.hits: list[dict] = []
        self.cut = False  # the trace reached its limit
        self.hits_cut = False
        self.start = machine.cycle
        self._skip = True

    def before(self, mpu) -> None:
        self._cycle = mpu.processorCycles
        self._sp = mpu.sp
        self._carry = mpu.p & 1
        self._interrupt = mpu.pending_interrupt if mpu.lines is not None else None
        pc = self._pc = mpu.pc
        b = self.bounds
        traced = b is not None and not self.cut and b.low <= pc <= b.high and (
            b.first_cycle is None or self._cycle - self.start >= b.first_cycle) and (
            b.last_cycle is None or self._cycle - self.start <= b.last_cycle)
        self._traced = traced
        self._operand = self._read = None
        if self._interrupt is None and (traced or self.watches):
            mnemonic, mode = mpu.disassemble[mpu.memory[pc]]
            self._mnemonic = mnemonic
            if mnemonic not in ("JMP", "JSR"):
                self._operand = self.machine._operand_address(pc, mode)
            if self._operand is not None and mnemonic not in STORES and mnemonic not in LOADS:
                self._read = self.peek(self._operand)
        if self.inner is not None:
            self.inner.before(mpu)

    def after(self, mpu) -> None:
        if self._traced or self.watches:
            self._note(mpu)
        if self.inner is not None:
            self.inner.after(mpu)

    def _note(self, mpu) -> None:
        interrupt = self._interrupt
        writes: list[tuple[int, int]] = []
        read = None
        mnemonic = interrupt or self._mnemonic
        operand = self._operand
        if interrupt is None and operand is not None:
            if mnemonic in STORED:  # what reached the bus (a chip register may read back otherwise)
                writes.append((operand, STORED[mnemonic](mpu)))
            elif mnemonic in RMW_MNEMONICS:  # the result, worked out from the byte read (a chip may read back otherwise)
                writes.append((operand, RMW_RESULT[mnemonic](self._read, self._carry)))
            if mnemonic in LOADS:
                read = {"LDA": mpu.a, "LDX": mpu.x, "LDY": mpu.y, "LAX": mpu.a}[mnemonic]
            elif mnemonic not in STORES:
                read = self._read
        pushed = 3 if interrupt else PUSHES.get(mnemonic, 0)
        for k in range(pushed):
            address = STACK | ((self._sp - k) & 0xFF)
            writes.append((address, mpu.memory[address]))
        if self.watches:
            self._watch(mpu, mnemonic, operand, read, writes, interrupt)
        if self._traced:
            if self.bounds.limit is not None and len(self.entries) >= self.bounds.limit:
                self.cut = True
                return
            self.entries.append(self._entry(mpu, mnemonic, operand, read, writes))

    def _where(self, cycle: int) -> dict:
        out = {"cycle": cycle - self.start}
        if self.position is not None:
            frame, line, column = self.position(cycle)
            out.update(frame=frame, line=line, at=column)
        return out

    def _entry(self, mpu, mnemonic, operand, read, writes) -> dict:
        p = (mpu.p | FLAG_U) & ~FLAG_B
        text = mnemonic if self._interrupt else self.machine.disassemble_at(self._pc)
        entry = {**self._where(self._cycle), "pc": self._pc, "op": text, "cycles": mpu.processorCycles - self._cycle,
                 "a": mpu.a, "x": mpu.x, "y": mpu.y, "s": mpu.sp, "p": p, "flags": flags_text(p)}
        if read is not None:
            entry["read"] = [operand, read]
        if writes:
            entry["writes"] = [list(w) for w in writes]
        return entry

    def _watch(self, mpu, mnemonic, operand, read, writes, interrupt) -> None:
        for watch in self.watches:
            hit = None
            if watch.kind == "x" and interrupt is None and watch.matches(self._pc):
                hit = ("exec", self._pc, mpu.a)
            if hit is None and watch.kind in ("r", "rw") and read is not None and watch.matches(operand):
                hit = ("read", operand, read)
            if hit is None and watch.kind in ("w", "rw"):
                hit = next((("write", a, v) for a, v in writes if watch.matches(a)), None)
            if hit is None or (watch.value is not None and hit[2] != watch.value):
                continue
            if len(self.hits) >= MAX_HITS:
                self.hits_cut = True
                return
            text = interrupt or self.machine.disassemble_at(self._pc)
            self.hits.append({"watch": watch.text, **self._where(self._cycle), "pc": self._pc, "op": text,
                              "access": hit[0], "address": hit[1], "value": hit[2]})


def entry_text(entry: dict, unit: str) -> str:
    where = (f"{entry['frame']}.{entry['line']:03d}.{entry['at']:03d} " if "line" in entry else "")
    read = f" read ${entry['read'][1]:02X}@${entry['read'][0]:04X}" if "read" in entry else ""
    writes = "".join(f" ${a:04X}=${v:02X}" for a, v in entry.get("writes", ()))
    return (f"{entry['cycle']:>9} {where}${entry['pc']:04X}  {entry['op']:<14} A={entry['a']:02X} X={entry['x']:02X} "
            f"Y={entry['y']:02X} S={entry['s']:02X} {entry['flags']}{read}{writes}")


def hit_text(hit: dict, unit: str) -> str:
    where = f" frame {hit['frame']} {unit} {hit['line']} at {hit['at']}" if "line" in hit else ""
    return (f"watch {hit['watch']}: {hit['access']} ${hit['address']:04X} = ${hit['value']:02X} at cycle "
            f"{hit['cycle']}{where}: ${hit['pc']:04X} {hit['op']}")
