"""What stands behind a change past the sweep's reach: an SMT proof (retro.optimize.smt) that the
new routine leaves the spec's outputs (and `--preserve`d registers) as the old one does.

First the whole routine, from its entry: its inputs, free registers, free flags and every byte
nothing sets are free variables; what the spec states (`[entry]`) and the bytes a call starts with
(the program outside the routine's code, `[memory]`) are as the check has them; an RTS ends a path.
A counterexample is then an entry state of the routine, replayed on the batched core before it
joins the test set. When the whole routine is out of the translation's reach (a JSR, a loop, the
stack), the changed fragment alone, from every state at its start (the bytes a call starts with
and D only when nothing in the routine can change them), equal on what is live after it; its
counterexample is a state inside the routine, which proves nothing about the routine's inputs and
joins nothing, unless the fragment starts at the entry (then it is an entry state, replayed as above)."""

from __future__ import annotations

from dataclasses import dataclass

from retro.optimize import smt
from retro.optimize.code import Instruction, Listing
from retro.optimize.effects import ALL_MEMORY, READ_MODIFY_WRITE, STORES, effects, known, live_after
from retro.routines.entry import EntryState
from retro.routines.places import FLAGS
from retro.routines.spec import Routine
from retro.routines.where import input_ranges

FIXED_LIMIT = 4096  # bytes a call starts with that a proof assumes at most (past it: none, still sound)
FLAG_NAME = {bit: name for name, bit in FLAGS.items()}
WRITES_D = frozenset({"SED", "CLD", "PLP", "RTI"})


@dataclass
class Counterexample:
    """A routine entry state: input values (by port), free registers and P bits, and bytes."""

    inputs: list
    registers: dict
    bits: int
    memory: dict


@dataclass
class Verdict:
    scope: str  # "routine" or "fragment"
    result: smt.Result
    counterexample: Counterexample | None = None

    def record(self) -> dict:
        return {"scope": self.scope, **self.result.record()}


def _reach(instructions) -> list[tuple[int, int]] | None:
    """Address ranges [start, end) the instructions may read; None: anywhere (a pointer)."""
    ranges = []
    for i in instructions:
        if i.target is not None or i.operand is None or i.mode in ("imm", "rel"):
            continue
        if i.mode in ("inx", "iny"):
            return None
        if i.mode in ("zpx", "zpy"):
            ranges.append((0, 0x100))
        elif i.mode in ("abx", "aby"):
            ranges.append((i.operand, min(i.operand + 0x100, 0x10000)))
        else:
            ranges.append((i.operand, i.operand + 1))
    return ranges


class Formal:
    """The SMT side of a search: the spec's entry facts and the bytes a call starts with, computed once."""

    def __init__(self, routine: Routine, image, size: int, at_return: frozenset, contents: dict) -> None:
        """`image`: memory as a call starts (the baseline's); `contents`: each [memory] block's bytes."""
        self.routine, self.cpu, self.size, self.at_return = routine, routine.cpu, size, at_return
        entry = EntryState.of(routine.entry_state, routine.inputs)
        taken = {p.register for port in routine.inputs for p in port.places if p.kind == "register"}
        taken_flags = {FLAG_NAME[p.bit] for port in routine.inputs for p in port.places if p.kind == "flag"}
        self.registers = {n: v for n, v in entry.registers.items() if n not in entry.free_registers and n not in taken}
        self.flags = {n: bool(entry.flags & FLAGS[n]) for n in FLAGS
                      if n not in entry.free_flags and n not in taken_flags and n in smt.FLAG_NAMES}
        program = routine.program
        inputs = {p.address for port in routine.inputs for p in port.places if p.kind == "memory" and port.via is None}
        # an output's bytes are random on entry in the search's runs (evaluate.scratch_of): never assumed
        outputs = {p.address for port in routine.outputs for p in port.places if p.kind == "memory"}
        code = range(routine.entry_address, routine.entry_address + size)
        spans = [(program.origin, program.end)]
        spans += [(b.address, b.address + len(contents[b.name])) for b in routine.memory]
        self.starts_with = {a: int(image[a]) for lo, hi in spans for a in range(lo, min(hi, 0x10000))
                            if a not in code and a not in inputs and a not in outputs}
        self.code_range = (routine.entry_address, routine.entry_address + size)
        self.shown = tuple(sorted(inputs))
        self.inputs = _input_facts(routine)

    def _fixed(self, instructions) -> dict:
        reach = _reach(instructions)
        if reach is None:
            chosen = self.starts_with
        else:
            chosen = {a: v for lo, hi in reach for a in range(lo, hi) if (v := self.starts_with.get(a)) is not None}
        return chosen if len(chosen) <= FIXED_LIMIT else {}

    def prove(self, old: Listing, new: Listing) -> Verdict | None:
        """The proof that `new` may replace `old` (None when they are the same code)."""
        span = smt.changed_fragments(old, new)
        if span is None:
            return None
        before = smt.Fragment(old.instructions, old.origin, dict(old.labels), self.cpu, returns=True)
        after = smt.Fragment(new.instructions, new.origin, dict(new.labels), self.cpu, returns=True)
        if all(smt.supported(i, self.cpu) or i.mnemonic == "RTS" or smt.jumps_ahead(i)
               for i in old.instructions + new.instructions):
            assumptions = smt.Assumptions(self._fixed(old.instructions + new.instructions), dict(self.registers),
                                          dict(self.flags), self.inputs, self.code_range)
            result = smt.prove_equivalent(before, after, self.at_return, assumptions, shown=self.shown)
            if result.status != "unsupported":
                return Verdict("routine", result, self._counterexample(result))
        result = self._prove_fragment(old, new, span)
        # a fragment at the entry starts from the routine's entry state: its counterexample is one
        return Verdict("fragment", result, self._counterexample(result) if span[0] == 0 else None)

    def _prove_fragment(self, old: Listing, new: Listing, span: tuple[int, int, int]) -> smt.Result:
        start, stop_old, stop_new = span
        try:
            before = smt.fragment_of(old, start, stop_old, self.cpu)
            after = smt.fragment_of(new, start, stop_new, self.cpu)
        except smt.Unsupported as exc:
            return smt.Result("unsupported", str(exc))
        # what holds at the fragment's start on every arrival: a loop may come back to it after the
        # fragment itself ran, so its own instructions (old and new) count with the rest of the routine
        everything = old.instructions + after.instructions
        stable = all(known(i) and i.mnemonic not in ("JSR", "JMP", "RTI", "BRK")
                     and _stores_known(i, self.starts_with, self.code_range) for i in everything if i.mnemonic != "RTS")
        flags = {}
        if "D" in self.flags and not any(i.mnemonic in WRITES_D or not known(i) or i.mnemonic == "JSR"
                                         for i in everything):
            flags["D"] = self.flags["D"]
        # unstable: a store somewhere may have changed any byte, so none is assumed
        fixed = self._fixed(before.instructions + after.instructions) if stable else {}
        assumptions = smt.Assumptions(fixed, flags=flags, code_range=self.code_range)
        live = live_after(old, self.at_return)[stop_old - 1]
        return smt.prove_equivalent(before, after, live, assumptions, shown=self.shown)

    def _counterexample(self, result: smt.Result) -> Counterexample | None:
        """The model as the routine's entry state (inputs by port), when every input is a plain
        number in registers, flags or fixed bytes."""
        if result.status != "refuted":
            return None
        model = result.model
        values = []
        for port in self.routine.inputs:
            if port.via is not None or port.table:
                return None
            value = 0
            for k, place in enumerate(port.places):
                if place.kind == "register":
                    part = model[place.register]
                elif place.kind == "flag":
                    part = int(model[FLAG_NAME[place.bit]])
                elif place.kind == "memory":
                    part = model["memory"].get(place.address, 0)
                else:
                    return None
                value |= part << (8 * k)
            values.append(value)
        registers = {n: model[n] for n in ("a", "x", "y")}
        bits = sum(FLAGS[n] for n in smt.FLAG_NAMES if model[n])
        memory = {a: v for a, v in model["memory"].items() if a not in self.shown}
        return Counterexample(values, registers, bits, memory)


LISTED_LIMIT = 256  # an input's listed values given to z3 one by one at most (past it: their range)


def _input_facts(routine: Routine) -> tuple:
    """The inputs' values as the spec's domain narrows them to ranges (retro.routines.where): z3
    proves the routine on them, as `retro check` does (a condition that is not a range is left out:
    the proof then covers more than the domain)."""
    plain = [p for p in routine.inputs if not p.table and p.via is None and p.values is not None
             and all(place.kind in ("register", "flag", "memory") for place in p.places)]
    ranges = input_ranges(routine.domain, {p.name: (p.values.lo, p.values.hi) for p in plain})
    facts = []
    for port in plain:
        lo, hi = ranges[port.name]
        listed = port.values.listed
        if listed is not None:
            listed = tuple(v for v in listed if lo <= v <= hi)
            if len(listed) > LISTED_LIMIT:
                lo, hi, listed = min(listed), max(listed), None
        if lo > hi or listed == ():
            continue  # an empty domain: the check has no case there either, and z3 needs no fact
        places = tuple(("register", p.register) if p.kind == "register" else ("flag", FLAG_NAME[p.bit])
                       if p.kind == "flag" else ("memory", p.address) for p in port.places)
        facts.append((places, lo, hi, listed))
    return tuple(facts)


def _stores_known(instruction: Instruction, starts_with: dict, code_range: tuple[int, int]) -> bool:
    """Whether the instruction's stores land at known addresses outside the bytes a proof assumes."""
    name = instruction.mnemonic
    if name not in STORES and name not in READ_MODIFY_WRITE or instruction.mode in ("acc", "imp"):
        return True
    _, _, _, written = effects(instruction)
    if not written or ALL_MEMORY in written:
        return False
    return all(a not in starts_with and not code_range[0] <= a < code_range[1] for a in written)
