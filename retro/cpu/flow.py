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
from retro.cpu.values import ANY, MemoryModel, State, execute, is_empty, narrowed, single
from retro.errors import InputError

OPCODE_JMP_ABS = 0x4C
OPCODE_JSR = 0x20
OPCODE_RTS = 0x60
OPCODE_RTI = 0x40
UNSUPPORTED = {0x6C: "JMP (indirect)", 0x40: "RTI", 0x00: "BRK"}
# The 65C02's: a jump through a table indexed by X (its target is data), and the two that stop the clock.
UNSUPPORTED_65C02 = {**UNSUPPORTED, 0x7C: "JMP (abs,X)", 0xCB: "WAI", 0xDB: "STP"}
JSR_LENGTH = 3


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
    ends = frozenset({OPCODE_RTS, OPCODE_RTI}) if interrupt else frozenset({OPCODE_RTS})
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
    key = (entry, entry_state)
    if key in context.done:
        return context.done[key]
    name, describe, within = context.name, context.describe, context.within
    bounds = context.bounds

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
    loops = _loops(nodes, entry)
    for header in loops:
        if header not in bounds:
            raise InputError(f"{name}: the loop at {describe(header)} needs a bound (the most times it runs per "
                             f"entry), e.g. [cycles] loops = {{ LABEL = N }} with a label at its first instruction")
    # Loops ordered outermost first (a larger body contains the smaller ones nested in it).
    order = sorted(loops, key=lambda h: -len(loops[h]))
    containing = {pc: tuple(h for h in order if pc in loops[h]) for pc in nodes}

    def next_state(state, target: int):
        source_pc, counts = state
        active = dict(zip(containing[source_pc], counts))
        new_counts = []
        for header in containing[target]:
            if header == target:
                count = active[header] + 1 if header in active else 1
                if count > bounds[header]:
                    return None
            elif header in active:
                count = active[header]
            else:
                raise InputError(f"{name}: ${target:04X} enters the loop at ${header:04X} other than through its start")
            new_counts.append(count)
        return target, tuple(new_counts)

    start = (entry, tuple(1 for _ in containing[entry]))
    topological = _topological(start, lambda state: [s for s in (next_state(state, t) for t, _ in
                                                                  nodes[state[0]].successors) if s is not None])
    values: dict = {start: entry_state}
    edges: dict = {}  # state -> [(next state, extra cycles)] of the ways the values allow
    costs: dict = {}  # state -> (least, most) cycles of its instruction
    exit_state: State | None = None
    writes: dict[int, set[int]] = {}  # address -> the stores that may write it
    memory = context.memory
    binary_only = context.cpu == "2a03"
    for state in topological:
        here = values.pop(state, None)
        if here is None:
            continue  # no way the values allow reaches it
        pc = state[0]
        node = nodes[pc]
        fact = context.facts.get(pc)
        if fact is not None:
            for register, mask in fact.registers:
                here = narrowed(here, register, mask)
            if is_empty(here):
                continue
        if pc in context.exits:  # the routine ends here (the JMP that reached it was counted)
            costs[state] = (0, 0)
            exit_state = here if exit_state is None else exit_state.join(here, memory)
            edges[state] = []
            continue
        opcode = context.read(pc)
        op = timing_of(opcode, context.cpu)
        taken_state = after = None
        if opcode == OPCODE_JSR and _jsr_target(context.read, pc) in context.mocks:
            cost = context.mocks[_jsr_target(context.read, pc)]
            costs[state] = (op.cycles + cost, op.cycles + cost)
            after = State()  # what a mock leaves is not followed: any value
        elif opcode == OPCODE_JSR:
            callee = _analyse(context, _jsr_target(context.read, pc), _called(here), (*calling, entry))
            for address, stores in callee.writes.items():
                writes.setdefault(address, set()).update(stores)
            if callee.exit is None:
                continue
            after = _returned(callee.exit)
            costs[state] = (op.cycles + callee.best, op.cycles + callee.worst)
        elif opcode == OPCODE_RTS or opcode in context.ends:
            costs[state] = (op.cycles, op.cycles)
            exit_state = here if exit_state is None else exit_state.join(here, memory)
            edges[state] = []
            continue
        elif opcode == OPCODE_JMP_ABS:
            costs[state] = (op.cycles, op.cycles)
            taken_state = here
        else:
            step = execute(here, memory, pc, op.mnemonic, op.mode, context.cpu, binary_only, op.page_penalty)
            if step.writes is not None:  # an unknown address: assumed outside the program (_check_modified)
                for address in step.writes:
                    writes.setdefault(address, set()).add(pc)
            costs[state] = (op.cycles + step.extra[0], op.cycles + step.extra[1])
            after, taken_state = step.after, step.taken
            if fact is not None and fact.taken is not None:
                after, taken_state = (None, taken_state) if fact.taken else (after, None)
        if op.mode in ("rel", "zpr") and op.mnemonic != "BRA":
            flows = (after, taken_state)  # decode lists the way through first, then the branch
        elif op.mode in ("rel", "zpr") or opcode == OPCODE_JMP_ABS:
            flows = (taken_state,)
        else:
            flows = (after,)
        ways = []
        for (target, extra), flowing in zip(node.successors, flows):
            if flowing is None:
                continue
            successor = next_state(state, target)
            if successor is None:
                continue
            ways.append((successor, extra))
            values[successor] = flowing if successor not in values else values[successor].join(flowing, memory)
        edges[state] = ways
    best: dict = {}
    worst: dict = {}
    for state in reversed(topological):
        if state not in costs:
            continue
        low, high = costs[state]
        if nodes[state[0]].returns:
            best[state], worst[state] = low, high
            continue
        options = [(best[s] + extra, worst[s] + extra) for s, extra in edges.get(state, []) if s in worst]
        if options:
            best[state] = low + min(b for b, _ in options)
            worst[state] = high + max(w for _, w in options)
    if start not in worst:
        raise InputError(f"{name}: no path from {describe(entry)} reaches an RTS within the loop bounds")
    summary = _Summary(best[start], worst[start], exit_state, len(nodes), writes)
    context.done[key] = summary
    return summary


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
