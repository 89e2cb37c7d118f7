"""Static best/worst-case cycles of a routine from its code as loaded, by control-flow analysis with
the values flowing along the paths.

The routine is decoded from its entry, following both ways of every branch and JMP absolute, up to
each RTS (on the 65C02 also BRA, always taken, and BBR/BBS, both ways). Loops: every back edge of
the decoded graph closes a loop whose header needs a bound, the most times the header runs per entry
into the loop (`loop_bounds`: header address -> count). The paths are then walked over the graph of
states (instruction, iteration counts of the loops it is in), which is acyclic because each count
only grows within one entry into its loop, so a loop is unrolled up to its bound.

Along that graph an abstract interpretation (retro.cpu.values) carries, per state, the sets of
values A, X, Y, the flags and the bytes the routine stored may hold, from the entry state (the
spec's inputs and their `values`; anything where the spec says nothing) and the memory on entry
(the code and tables as loaded, constant `[memory]` blocks). With them:
- a branch whose flag is known goes one way only (`LDA #0 / BEQ` is always taken; `LDX #3 ... DEX
  / BNE` runs its loop exactly three times);
- an indexed read pays its page crossing only when some value of its base's low byte plus some
  value of the index passes $FF (both bounds pay it when every pair does): `LDY #0 / LDA tbl,Y`
  never crosses, a spec fixing X gives `LDA obj,X` its exact cost;
- a store into the routine's own code (self-modifying code) is followed: the operand byte an
  instruction reads is whatever the path stored there, so the crossing is decided from the values
  that may be stored; a store that may reach an opcode, or the operand of a branch, JMP or JSR, stops
  the analysis with a message naming both (it cannot bound code whose instructions change);
- a JSR is analysed from the state at the call (its cost and the state after its RTS).
Facts the spec states (`Fact`: a branch always or never taken, register sets at an address) narrow
the states further; the check holds every case against them.

The result is an over-approximation: paths the data can never take may remain (values are sets,
not relations between registers), so the static worst case bounds every run and may not be reached;
it is never below a run that starts inside the entry state.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from retro.cpu.timing import (
    BRANCH_PAGE_CYCLES,
    BRANCH_TAKEN_CYCLES,
    WDC_65C02,
    TimingError,
    branch_target,
    crosses_page,
    timing_of,
)
from retro.cpu.value_steps import execute
from retro.cpu.values import ANY, MemoryModel, State, is_empty, narrowed, single
from retro.errors import InputError

OPCODE_JMP_ABS = 0x4C
OPCODE_JSR = 0x20
OPCODE_RTS = 0x60
OPCODE_RTI = 0x40
UNSUPPORTED = {0x6C: "JMP (indirect)", 0x40: "RTI", 0x00: "BRK"}
# The 65C02's: a jump through a table indexed by X (its target is data), and the two that stop the clock.
UNSUPPORTED_65C02 = {**UNSUPPORTED, 0x7C: "JMP (abs,X)", 0xCB: "WAI", 0xDB: "STP"}
JSR_LENGTH = 3


def return_opcodes(interrupt: bool) -> frozenset[int]:
    """The opcodes that end a routine: RTS, and RTI too when its entry is an interrupt handler."""
    return frozenset({OPCODE_RTS, OPCODE_RTI}) if interrupt else frozenset({OPCODE_RTS})


@dataclass
class Node:
    pc: int
    successors: list[tuple[int, int]] = field(default_factory=list)  # (pc, extra cycles on that edge)
    returns: bool = False


def decode(read: Callable[[int], int], entry: int,
           call_cost: Callable[[int, int], tuple[int, int]] | None = None, cpu: str = "6510",
           ends: frozenset[int] = frozenset({OPCODE_RTS}), exits: frozenset[int] = frozenset()) -> dict[int, Node]:
    """The instructions reachable from entry, from the bytes `read` gives (their cycles are decided
    per state by `analyse`). A JSR continues after it, as the callee's RTS returns there;
    `call_cost(pc, target)` is told of every JSR (it may refuse it with an InputError).
    `ends`: the opcodes that return (an interrupt handler's RTI); `exits`: addresses whose reaching
    ends the routine at no cost (a JMP to a named exit: the JMP is counted, nothing after it)."""
    cmos = cpu == WDC_65C02
    unsupported = {k: v for k, v in (UNSUPPORTED_65C02 if cmos else UNSUPPORTED).items() if k not in ends}
    nodes: dict[int, Node] = {}
    pending = [entry]
    while pending:
        pc = pending.pop()
        if pc in nodes:
            continue
        if pc in exits:
            nodes[pc] = Node(pc, returns=True)
            continue
        opcode = read(pc)
        if opcode in unsupported or (opcode == OPCODE_JSR and call_cost is None):
            name = unsupported.get(opcode, "JSR")
            raise InputError(f"${pc:04X}: {name} is not supported by the static analysis")
        try:
            op = timing_of(opcode, cpu)
        except TimingError:
            raise InputError(f"${pc:04X}: opcode ${opcode:02X} is not an instruction the {cpu.upper()} runs "
                             f"(a JAM or unstable opcode; is the CPU right? program.cpu)") from None
        operand = read((pc + 1) & 0xFFFF) | read((pc + 2) & 0xFFFF) << 8
        node = Node(pc)
        following = (pc + op.length) & 0xFFFF
        if opcode == OPCODE_JSR:
            call_cost(pc, operand)
            node.successors.append((following, 0))
        elif opcode == OPCODE_RTS or opcode in ends:
            node.returns = True
        elif opcode == OPCODE_JMP_ABS:
            node.successors.append((operand, 0))
        elif op.mode in ("rel", "zpr"):  # zpr: BBR/BBS, the offset in their third byte
            offset = operand & 0xFF if op.mode == "rel" else operand >> 8
            target = branch_target(pc, offset, op.length)
            taken = BRANCH_TAKEN_CYCLES + (BRANCH_PAGE_CYCLES if crosses_page(following, target) else 0)
            if op.mnemonic == "BRA":
                node.successors.append((target, taken))
            else:  # the way through first, then the branch (analyse relies on the order)
                node.successors += [(following, 0), (target, taken)]
        else:
            node.successors.append((following, 0))
        nodes[pc] = node
        pending.extend(s for s, _ in node.successors)
    return nodes


def _loops(nodes: dict[int, Node], entry: int) -> dict[int, frozenset[int]]:
    """Header -> body (natural loops of the back edges found by depth-first search)."""
    back_edges: list[tuple[int, int]] = []
    state: dict[int, int] = {}  # 1 on the stack, 2 done
    stack = [(entry, iter(nodes[entry].successors))]
    state[entry] = 1
    while stack:
        pc, successors = stack[-1]
        for target, _ in successors:
            if state.get(target) == 1:
                back_edges.append((pc, target))
            elif target not in state:
                state[target] = 1
                stack.append((target, iter(nodes[target].successors)))
                break
        else:
            state[pc] = 2
            stack.pop()
    predecessors: dict[int, set[int]] = {pc: set() for pc in nodes}
    for pc, node in nodes.items():
        for target, _ in node.successors:
            predecessors[target].add(pc)
    loops: dict[int, set[int]] = {}
    for tail, header in back_edges:
        body = loops.setdefault(header, {header})
        work = [tail]
        while work:
            pc = work.pop()
            if pc not in body:
                body.add(pc)
                work.extend(predecessors[pc])
    return {header: frozenset(body) for header, body in loops.items()}



@dataclass(frozen=True)
class Fact:
    """What a spec states at one address and the analysis cannot derive: the branch there always
    (True) or never (False) taken, and/or the sets its registers and flags hold (retro.cpu.values)."""

    taken: bool | None = None
    registers: tuple[tuple[str, int], ...] = ()  # ("a" | "x" | "y" | "c" | ..., set)


@dataclass(frozen=True)
class Bounds:
    best: int
    worst: int
    instructions: int  # distinct instructions reachable from the entry
    modified: tuple[str, ...] = ()  # self-modifying code: each store into the routine's code and what it bounds


@dataclass(frozen=True)
class _Summary:
    best: int
    worst: int
    exit: State | None  # the state after the RTS (joined over every way out)
    instructions: int
    writes: dict[int, set[int]]  # every known address a store may reach -> the stores' addresses


def analyse(read: Callable[[int], int], entry: int, loop_bounds: dict[int, int] | None = None,
            name: str = "routine", within: tuple[int, int] | None = None,
            describe: Callable[[int], str] | None = None, cpu: str = "6510", *,
            memory: MemoryModel | None = None, entry_state: State | None = None,
            facts: dict[int, Fact] | None = None, mocks: dict[int, int] | None = None, interrupt: bool = False,
            exits: frozenset[int] = frozenset()) -> Bounds:
    """Best and worst cycles from the entry through an RTS over every path the bytes and the values
    allow (module docstring).

    `read` gives the code as loaded. `memory` says what every byte may hold on entry (default: the
    decoded instructions' bytes as `read` gives them, anything else unknown); `entry_state` the
    registers and flags (default: any value); `facts` what the spec states at addresses. Subroutines
    called with JSR are analysed from the state at each call (their loops bounded by the same
    `loop_bounds`), as long as they lie in `within` (start, end) when given; recursion is an error.
    `describe(address)` names an address in errors (a label). A routine's world (retro.routines.world):
    `mocks` {JSR target: its cycles through its RTS}, `interrupt` (the entry is a handler: its RTI ends
    it), `exits` (reaching one ends it); the interrupt sequence's own cycles are the caller's to add."""
    describe = describe or (lambda a: f"${a:04X}")
    ends = return_opcodes(interrupt)
    if memory is None:
        code: set[int] = set()
        for pc, length in instruction_lengths(read, [entry], within, cpu, ends=ends, exits=exits).items():
            code.update((pc + k) & 0xFFFF for k in range(length))
        memory = MemoryModel(lambda address: single(read(address)) if address in code else ANY,
                             within or (0, 0))
    context = _Context(read, dict(loop_bounds or {}), name, within, describe, cpu, memory, facts or {}, {},
                       dict(mocks or {}), ends, frozenset(exits))
    summary = _analyse(context, entry, entry_state or State(), ())
    modified = _check_modified(context, summary.writes)
    return Bounds(best=summary.best, worst=summary.worst, instructions=summary.instructions, modified=modified)


def instruction_lengths(read, entries: list[int], within: tuple[int, int] | None, cpu: str = "6510",
                        skip_undecodable: bool = False, ends: frozenset[int] = frozenset({OPCODE_RTS}),
                        exits: frozenset[int] = frozenset()) -> dict[int, int]:
    """{pc: length} of every instruction reachable from the entries, following branches, JMP and JSR
    into `within` (None: anywhere), as `decode` reads them. `skip_undecodable`: an entry whose code
    the decoder does not follow counts none of its code (else its InputError is raised)."""
    found: dict[int, int] = {}
    pending = list(entries)
    while pending:
        start = pending.pop()
        if start in found:
            continue
        callees: list[int] = []

        def note(pc: int, target: int) -> tuple[int, int]:
            if within is None or within[0] <= target < within[1]:
                callees.append(target)
            return (0, 0)
        try:
            nodes = decode(read, start, note, cpu, ends, exits)
        except (InputError, KeyError, ValueError):
            if not skip_undecodable:
                raise
            continue
        for pc in nodes:
            if pc not in exits:  # an exit's instruction is not the routine's
                found[pc] = timing_of(read(pc), cpu).length
        pending.extend(callees)
    return found


@dataclass
class _Context:
    read: Callable[[int], int]
    bounds: dict[int, int]
    name: str
    within: tuple[int, int] | None
    describe: Callable[[int], str]
    cpu: str
    memory: MemoryModel
    facts: dict[int, Fact]
    done: dict  # (entry, state) -> _Summary
    mocks: dict[int, int] = field(default_factory=dict)  # a mocked JSR target -> its cycles through its RTS
    ends: frozenset[int] = frozenset({OPCODE_RTS})  # the opcodes that end the routine
    exits: frozenset[int] = frozenset()  # addresses whose reaching ends it
    nodes: dict[int, Node] = field(default_factory=dict)  # every decoded instruction of every routine


def _analyse(context: _Context, entry: int, entry_state: State, calling: tuple) -> _Summary:
    """The routine (or subroutine) at `entry` from `entry_state`, once per (entry, state)."""
    key = (entry, entry_state)
    if key not in context.done:
        nodes = _decode_routine(context, entry, calling)
        walk = _Walk(context, nodes, _LoopNest(context, nodes, entry), (*calling, entry))
        context.done[key] = walk.summary(entry, entry_state)
    return context.done[key]


def _decode_routine(context: _Context, entry: int, calling: tuple) -> dict[int, Node]:
    """The routine's instructions; a JSR outside the program (unless mocked), a recursive one, or a
    subroutine reaching an exit is an error."""
    name, describe, within = context.name, context.describe, context.within

    def check_call(pc: int, target: int) -> tuple[int, int]:
        if target in context.mocks:
            return (0, 0)
        if within is not None and not within[0] <= target < within[1]:
            raise InputError(f"{name}: JSR {describe(target)} at ${pc:04X} calls outside the program "
                             f"(${within[0]:04X}-${within[1] - 1:04X}); its cost is unknown: say what it does and costs "
                             "with a mock ([mocks], docs/specs.md)")
        if target in calling or target == entry:
            raise InputError(f"{name}: JSR {describe(target)} at ${pc:04X} is recursive")
        return (0, 0)

    nodes = decode(context.read, entry, check_call, context.cpu, context.ends, context.exits)
    context.nodes.update(nodes)
    reached = sorted(pc for pc in nodes if pc in context.exits)
    if calling and reached:  # the call would end inside a subroutine: its caller's rest is not run
        raise InputError(f"{name}: the subroutine at {describe(entry)} reaches the exit {describe(reached[0])}; the "
                         "static analysis bounds exits reached by the routine itself, not by its subroutines")
    return nodes


class _LoopNest:
    """The routine's loops and the states of its acyclic graph: (pc, the iteration count of every
    loop the pc is in, outermost first)."""

    def __init__(self, context: _Context, nodes: dict[int, Node], entry: int) -> None:
        loops = _loops(nodes, entry)
        for header in loops:
            if header not in context.bounds:
                raise InputError(f"{context.name}: the loop at {context.describe(header)} needs a bound (the most "
                                 f"times it runs per entry), e.g. [cycles] loops = {{ LABEL = N }} with a label at "
                                 f"its first instruction")
        # Loops ordered outermost first (a larger body contains the smaller ones nested in it).
        order = sorted(loops, key=lambda h: -len(loops[h]))
        self.containing = {pc: tuple(h for h in order if pc in loops[h]) for pc in nodes}
        self.bounds, self.name = context.bounds, context.name
        self.start = (entry, tuple(1 for _ in self.containing[entry]))

    def following(self, state: tuple, target: int) -> tuple | None:
        """The state after going from `state` to `target`; None past a loop's bound."""
        source_pc, counts = state
        active = dict(zip(self.containing[source_pc], counts))
        new_counts = []
        for header in self.containing[target]:
            if header == target:
                count = active[header] + 1 if header in active else 1
                if count > self.bounds[header]:
                    return None
            elif header in active:
                count = active[header]
            else:
                raise InputError(f"{self.name}: ${target:04X} enters the loop at ${header:04X} other than through "
                                 f"its start")
            new_counts.append(count)
        return target, tuple(new_counts)


@dataclass(frozen=True)
class _Effect:
    """One instruction in one state: its cycles (least, most), the state going on through it and
    the state where it branches or jumps (None: that way cannot happen), or the routine ends there."""

    cost: tuple[int, int]
    after: State | None = None
    taken: State | None = None
    ends: bool = False


class _Walk:
    """The values carried along one routine's acyclic graph of states, then its extremes."""

    def __init__(self, context: _Context, nodes: dict[int, Node], nest: _LoopNest, calling: tuple) -> None:
        self.context, self.nodes, self.nest, self.calling = context, nodes, nest, calling
        self.values: dict = {}  # state -> what the registers and memory may hold there
        self.edges: dict = {}  # state -> [(next state, extra cycles)] of the ways the values allow
        self.costs: dict = {}  # state -> (least, most) cycles of its instruction
        self.exit_state: State | None = None  # joined over every way out
        self.writes: dict[int, set[int]] = {}  # address -> the stores that may write it

    def summary(self, entry: int, entry_state: State) -> _Summary:
        start = self.nest.start
        order = _topological(start, self._successors)
        self.values[start] = entry_state
        for state in order:
            here = self.values.pop(state, None)
            if here is not None:  # else no way the values allow reaches it
                self._visit(state, here)
        best, worst = self._extremes(order)
        if start not in worst:
            raise InputError(f"{self.context.name}: no path from {self.context.describe(entry)} reaches an RTS "
                             f"within the loop bounds")
        return _Summary(best[start], worst[start], self.exit_state, len(self.nodes), self.writes)

    def _successors(self, state: tuple) -> list:
        following = (self.nest.following(state, t) for t, _ in self.nodes[state[0]].successors)
        return [s for s in following if s is not None]

    def _visit(self, state: tuple, here: State) -> None:
        pc = state[0]
        fact = self.context.facts.get(pc)
        if fact is not None:
            for register, mask in fact.registers:
                here = narrowed(here, register, mask)
            if is_empty(here):
                return
        effect = self._effect(pc, here, fact)
        if effect is None:
            return  # a subroutine that never returns
        self.costs[state] = effect.cost
        if effect.ends:
            self.exit_state = here if self.exit_state is None else self.exit_state.join(here, self.context.memory)
            self.edges[state] = []
            return
        self.edges[state] = self._flow(state, _flows(timing_of(self.context.read(pc), self.context.cpu), effect))

    def _flow(self, state: tuple, flows: tuple) -> list:
        """The ways on from `state`, each carrying its state (decode's successors, in its order)."""
        ways = []
        for (target, extra), flowing in zip(self.nodes[state[0]].successors, flows):
            successor = None if flowing is None else self.nest.following(state, target)
            if successor is None:
                continue
            ways.append((successor, extra))
            known = self.values.get(successor)
            self.values[successor] = flowing if known is None else known.join(flowing, self.context.memory)
        return ways

    def _effect(self, pc: int, here: State, fact: Fact | None) -> _Effect | None:
        context = self.context
        if pc in context.exits:  # the routine ends here (the JMP that reached it was counted)
            return _Effect((0, 0), ends=True)
        opcode = context.read(pc)
        op = timing_of(opcode, context.cpu)
        if opcode == OPCODE_JSR:
            return self._call(pc, here, op.cycles)
        if opcode == OPCODE_RTS or opcode in context.ends:
            return _Effect((op.cycles, op.cycles), ends=True)
        if opcode == OPCODE_JMP_ABS:
            return _Effect((op.cycles, op.cycles), taken=here)
        return self._step(pc, here, op, fact)

    def _call(self, pc: int, here: State, cycles: int) -> _Effect | None:
        """A JSR: a mock's cycles (what it leaves is not followed: any value), or the callee analysed
        from the state at the call (None when it never returns)."""
        target = _jsr_target(self.context.read, pc)
        if target in self.context.mocks:
            cost = cycles + self.context.mocks[target]
            return _Effect((cost, cost), after=State())
        callee = _analyse(self.context, target, _called(here), self.calling)
        for address, stores in callee.writes.items():
            self.writes.setdefault(address, set()).update(stores)
        if callee.exit is None:
            return None
        return _Effect((cycles + callee.best, cycles + callee.worst), after=_returned(callee.exit))

    def _step(self, pc: int, here: State, op, fact: Fact | None) -> _Effect:
        """Any other instruction, through retro.cpu.value_steps (a fact may decide its branch)."""
        context = self.context
        step = execute(here, context.memory, pc, op.mnemonic, op.mode, context.cpu, context.cpu == "2a03",
                       op.page_penalty)
        if step.writes is not None:  # an unknown address: assumed outside the program (_check_modified)
            for address in step.writes:
                self.writes.setdefault(address, set()).add(pc)
        after, taken = step.after, step.taken
        if fact is not None and fact.taken is not None:
            after, taken = (None, taken) if fact.taken else (after, None)
        return _Effect((op.cycles + step.extra[0], op.cycles + step.extra[1]), after, taken)

    def _extremes(self, order: list) -> tuple[dict, dict]:
        """Fewest and most cycles from each state through the end, last state first."""
        best: dict = {}
        worst: dict = {}
        for state in reversed(order):
            if state not in self.costs:
                continue
            low, high = self.costs[state]
            if self.nodes[state[0]].returns:
                best[state], worst[state] = low, high
                continue
            options = [(best[s] + extra, worst[s] + extra) for s, extra in self.edges.get(state, []) if s in worst]
            if options:
                best[state] = low + min(b for b, _ in options)
                worst[state] = high + max(w for _, w in options)
        return best, worst


def _flows(op, effect: _Effect) -> tuple:
    """The states along decode's successors of an instruction: a conditional branch's way through,
    then its branch; an unconditional branch's or JMP's target; else the way through."""
    if op.mode in ("rel", "zpr"):
        return (effect.after, effect.taken) if op.mnemonic != "BRA" else (effect.taken,)
    return (effect.taken,) if op.mnemonic == "JMP" else (effect.after,)


def _jsr_target(read, pc: int) -> int:
    return read((pc + 1) & 0xFFFF) | read((pc + 2) & 0xFFFF) << 8


def _called(state: State) -> State:
    """The state a subroutine starts in: the caller's, with the return address pushed."""
    return state.pushed(("a", ANY)).pushed(("a", ANY))


def _returned(state: State) -> State:
    """The caller's state after the RTS pulled the return address."""
    for _ in range(2):
        _, state = state.pulled()
    return state


def _topological(start, successors: Callable) -> list:
    """The states reachable from start, each before every state it leads to (the graph is acyclic)."""
    order: list = []
    seen = {start}
    stack = [(start, iter(successors(start)))]
    while stack:
        state, pending = stack[-1]
        for following in pending:
            if following not in seen:
                seen.add(following)
                stack.append((following, iter(successors(following))))
                break
        else:
            order.append(state)
            stack.pop()
    order.reverse()
    return order


def _check_modified(context: _Context, writes: dict[int, set[int]]) -> tuple[str, ...]:
    """Stores into the routine's own code: an operand of an instruction that reads data is followed
    (its values came through the analysis); an opcode, or the operand of a branch, JMP or JSR, cannot
    be: the analysis stops naming the instruction. A store to an unknown address is assumed not to
    reach the program (docs/specs.md)."""
    notes = []
    for pc in sorted(context.nodes):
        if pc in context.exits:
            continue  # an exit's byte is not the routine's (a trap stands there during a check)
        op = timing_of(context.read(pc), context.cpu)
        hit = [(pc + k) & 0xFFFF for k in range(op.length) if (pc + k) & 0xFFFF in writes]
        if not hit:
            continue
        where = context.describe(pc)
        writers = sorted(set().union(*(writes[a] for a in hit)))
        stores = ("the store at " if len(writers) == 1 else "the stores at ") + ", ".join(f"${s:04X}" for s in writers)
        if pc in hit:
            raise InputError(f"{context.name}: {stores} may rewrite the opcode of {op.mnemonic} at "
                             f"{where}: the static analysis cannot bound code whose instructions change")
        if op.mode in ("rel", "zpr") or op.mnemonic in ("JMP", "JSR"):
            raise InputError(f"{context.name}: {stores} may rewrite the target of {op.mnemonic} at "
                             f"{where}: the static analysis cannot bound a path whose jumps change")
        notes.append(f"{op.mnemonic} at {where}: its operand is written by {stores}; "
                     f"bounded from the values stored")
    return tuple(notes)
