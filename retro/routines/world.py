"""The routine's world: what a spec says about everything outside the routine's own bytes.

- **Mocks** (`[mocks]`): a JSR target outside the program whose effect the spec states: registers
  and flags it returns, bytes it writes, the cycles it costs, or a Python function of the machine
  state (run under the sandbox's guards). Every call is counted, its arguments (registers, flags,
  memory named in `args`) recorded; outputs can be the count (`{ calls = NAME }`) and the reference
  may take the list of calls by the mock's name.
- **Hardware** (`[hardware]`): an address whose reads the spec scripts (a list of values, the last
  one held, or a function of the read count and cycle) and whose writes are recorded; outputs can be
  the values written (`{ writes = NAME, size = N }`) or their count (`{ writes = NAME }`).
- **Entry and exit** (`[program] interrupt`, `[program] exit`): a routine entered as an IRQ or NMI
  handler (the interrupt sequence's pushes and 7 cycles, I set; it ends at the RTI that pops that
  frame), and addresses whose reaching ends the call (a JMP to a named exit instead of an RTS).

Both engines run all of it with the same results, through traps (retro.cpu.traps: the trap byte
written at every mock and exit address) and, for hardware, a device on Machine's bus or hooks on the
batched core's lane memory (a function mock is called lane by lane there); what the batched core
cannot run (a hardware function, timed per read; an NMOS read-modify-write of hardware) is said by
`batch_refusal`, and the check then runs on Machine and
says why. docs/specs.md, "The routine's world", is the user's view.

This module holds what a world is (plain data) and the rules both engines share (a function mock's
effects); a spec's sections are read in retro.routines.world_spec, the world runs on Machine in
retro.routines.world_machine and on the batched core in retro.routines.world_lanes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from retro.cpu.mpu import INTERRUPT_CYCLES
from retro.errors import InputError
from retro.routines.places import FLAGS, REGISTERS, Place
from retro.routines.sandbox import UserCodeError, shown

MAX_RECORDED = 1 << 16  # calls of one mock (or writes to one address) recorded in one call of the routine
FUNCTION_MOCK_ARGUMENTS = ("a", "x", "y", "p", "s", "count", "cycle", "memory")
HARDWARE_FUNCTION_ARGUMENTS = ("count", "cycle")
WORLD_PLACES = ("count", "written")  # Place kinds of world outputs (a count's byte, a written value)
_RESULT_KEYS = {*REGISTERS, *FLAGS, "writes"}


# ---- plain data ----------------------------------------------------------------------------------

@dataclass(frozen=True)
class Mock:
    """What a JSR to `address` does instead of running code there: its effects, then an RTS."""

    name: str
    address: int
    cycles: int  # from the callee's first cycle through its RTS (the caller's JSR is the caller's)
    registers: tuple[tuple[str, int], ...] = ()  # ("a", 7): registers it returns
    flags_set: int = 0
    flags_clear: int = 0
    writes: tuple[tuple[int, int], ...] = ()  # (address, byte) it stores
    args: tuple[tuple[str, Place], ...] = ()  # what each call records: (the spec's text, where)
    function: Callable | None = None  # a Python function of the machine state (its effects instead)
    parameters: tuple[str, ...] = ()  # of FUNCTION_MOCK_ARGUMENTS, those the function takes


@dataclass(frozen=True)
class Hardware:
    """An address whose reads are scripted and whose writes are recorded."""

    name: str
    address: int
    reads: tuple[int, ...] | None = None  # the values of the reads in order, the last one held
    function: Callable | None = None  # (count, cycle) -> byte
    parameters: tuple[str, ...] = ()
    rmw_at: int | None = None  # an NMOS read-modify-write of it in the program (its double write: Machine only)


@dataclass(frozen=True)
class World:
    mocks: tuple[Mock, ...] = ()
    hardware: tuple[Hardware, ...] = ()
    enter: str = "jsr"  # "jsr", "irq" or "nmi" (retro.cpu.machine.ENTRIES)
    exits: tuple[int, ...] = ()  # reaching one of these ends the call
    recorded: frozenset[str] = frozenset()  # mocks whose calls are kept (the reference takes them)

    @property
    def empty(self) -> bool:
        return not (self.mocks or self.hardware or self.exits) and self.enter == "jsr"

    @property
    def entry_cycles(self) -> int:
        """Cycles counted before the routine's first instruction: the interrupt sequence's."""
        return 0 if self.enter == "jsr" else INTERRUPT_CYCLES

    def batch_refusal(self) -> str | None:
        """Why the batched core cannot run this world (None: it can)."""
        for hardware in self.hardware:
            if hardware.function is not None:
                return f"hardware.{hardware.name}.function is a Python function, run per read on Machine"
            if hardware.rmw_at is not None:
                return (f"hardware.{hardware.name} (${hardware.address:04X}) is read-modified-written at "
                        f"${hardware.rmw_at:04X}, whose double write Machine models")
        return None

    def mock_costs(self) -> dict[int, int]:
        """Cycles of each mocked JSR target (its body through the RTS), for the static bounds."""
        return {m.address: m.cycles for m in self.mocks}


NO_WORLD = World()


def recorded_mocks(world: World, parameters: set[str], takes_any: bool) -> World:
    """The world with the mocks whose calls the reference takes by name marked as recorded."""
    names = frozenset(m.name for m in world.mocks if m.name in parameters or takes_any)
    return World(world.mocks, world.hardware, world.enter, world.exits, names)


def reference_calls(world: World) -> tuple[str, ...]:
    return tuple(m.name for m in world.mocks if m.name in world.recorded)


# ---- a function mock or hardware function, on either engine ------------------------------------

def function_effects(mock: Mock, state: dict, spec: str) -> tuple[list, int, int, list]:
    """A function mock called with the machine `state` it names: its effects, checked, as (registers,
    flags set, flags cleared, writes); the same on both engines (a one-line error for nonsense)."""
    count = state["count"]
    where = f"{spec}: mocks.{mock.name}.function"
    result = call_user(mock.function, mock.parameters, state, where, f"call {count}")
    registers, flags_set, flags_clear, writes = [], 0, 0, []
    if result is None:
        return registers, flags_set, flags_clear, writes
    if not isinstance(result, dict) or not set(result) <= _RESULT_KEYS:
        raise InputError(f"{where} returned {shown(result)} (call {count}): expected None or a dict with keys "
                         f"among {', '.join(sorted(_RESULT_KEYS))}")
    for key, value in result.items():
        if key == "writes":
            if not isinstance(value, dict):
                raise InputError(f"{where} returned writes = {shown(value)} (call {count}): expected {{address: byte}}")
            writes = [(whole(address, 0xFFFF, where, count), whole(byte, 0xFF, where, count))
                      for address, byte in value.items()]
        elif key in FLAGS:
            if whole(value, 1, where, count):
                flags_set |= FLAGS[key]
            else:
                flags_clear |= FLAGS[key]
        else:
            registers.append((key.lower(), whole(value, 0xFF, where, count)))
    return registers, flags_set, flags_clear, writes


def call_user(function: Callable, parameters: tuple[str, ...], state: dict, where: str, which: str):
    """A spec's function (already under the sandbox's guards) called with the state it names; whatever
    it raises is one line naming it and the call or read."""
    try:
        return function(**{name: state[name] for name in parameters})
    except UserCodeError:
        raise
    except Exception as exc:
        raise InputError(f"{where} raised {type(exc).__name__}: {str(exc)[:200]} ({which})") from None


def whole(value, most: int, where: str, count: int) -> int:
    if isinstance(value, bool):
        value = int(value)
    if isinstance(value, np.integer):
        value = int(value)
    if not isinstance(value, int) or not 0 <= value <= most:
        raise InputError(f"{where} returned {shown(value)} (call {count}): expected a whole number 0..{most}")
    return value

