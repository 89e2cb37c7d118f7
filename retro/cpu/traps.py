"""Traps: addresses where the CPU hands control to Python instead of running the byte stored there.

A routine's world (retro.routines.world) uses them for what lies outside the program: a mocked
subroutine (a JSR target whose effect the spec states) and a named exit (reaching it ends the call).
The trap byte, TRAP_OPCODE, is written at each trap address; on both engines its handler looks the
address up and runs the trap's action, and anywhere else it does what the opcode always does (a JAM
on the NMOS CPUs, a two-byte NOP on the 65C02), so a stray $02 in a program keeps its meaning.

- `Machine` (retro.cpu.mpu): `install_on_mpu` gives that one MPU its own copy of the dispatch table
  with the trap handler in it (the class's table, shared by every other MPU, is untouched). An action
  takes the MPU, does what it does (registers, memory, PC, S) and returns the cycles the trap costs.
- The batched core (retro.cpu.batch): `install_on_batch` puts the trap handler into that BatchCpu's
  handler table. An action takes the group of lanes at the trap (retro.cpu.batch.Lanes), adds its
  cycles itself and returns the next PC, as every handler of the batched core does.
"""

from __future__ import annotations

from collections.abc import Callable

TRAP_OPCODE = 0x02  # a JAM on the NMOS 6502: no working program runs it; the 65C02's reserved 2-byte NOP


def install_on_mpu(mpu, actions: dict[int, Callable]) -> None:
    """Run `actions[address](mpu) -> cycles` when `mpu` executes TRAP_OPCODE at one of the addresses."""
    original = type(mpu).instruct[TRAP_OPCODE]
    cycletime = mpu.cycletime

    def trap(self):
        action = actions.get((self.pc - 1) & 0xFFFF)
        if action is None:
            return original(self)
        self.excycles = action(self) - cycletime[TRAP_OPCODE]
        return None

    table = list(type(mpu).instruct)
    table[TRAP_OPCODE] = trap
    mpu.instruct = table  # this MPU's own table: run_until and step read self.instruct


def install_on_batch(cpu, actions: dict[int, Callable], stop_unknown: Callable) -> None:
    """Run `actions[pc](lanes) -> next pc` when lanes of `cpu` execute TRAP_OPCODE at one of the
    addresses; elsewhere the opcode's own handler, or `stop_unknown(lanes, pc)` when it has none."""
    original = cpu.handlers.get(TRAP_OPCODE)

    def trap(g, pc, lo, hi):
        action = actions.get(pc) if isinstance(pc, int) else None
        if action is not None:
            return action(g)
        if original is not None:
            return original(g, pc, lo, hi)
        stop_unknown(g, pc)
        return []

    cpu.handlers = {**cpu.handlers, TRAP_OPCODE: trap}
