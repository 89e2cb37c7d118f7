"""Static best/worst-case cycles of a routine from its bytes, by control-flow analysis.

The routine is decoded from its entry, following both ways of every branch and JMP absolute, up to
each RTS (on the 65C02 also BRA, always taken, and BBR/BBS, both ways). Each instruction costs its
datasheet cycles (retro.cpu.timing) plus the penalties the
bytes cannot rule out: an indexed read whose base address has a non-zero low byte may cross a page
(+0 or +1); an (indirect),Y read may always cross (its pointer is data); a taken branch costs +1,
and +1 more when its target lies in another page (known from the addresses); on the 65C02 an ADC
or SBC may run in decimal mode (+0 or +1: D is data).

Loops: every back edge of the decoded graph closes a loop whose header needs a bound, the most
times the header runs per entry into the loop (`loop_bounds`: header address -> count; the asm
headers state them). The analysis then takes the longest and shortest path through the graph of
states (instruction, iteration counts of the loops it is in), which is acyclic because each count
only grows within one entry into its loop. It is an over-approximation: paths the data can never
take are included, so the static worst case bounds every run and may not be reached.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from retro.cpu.timing import (
    BRANCH_PAGE_CYCLES,
    BRANCH_TAKEN_CYCLES,
    CMOS_DECIMAL_CYCLES,
    PAGE_CROSS_CYCLES,
    WDC_65C02,
    TimingError,
    branch_target,
    crosses_page,
    timing_of,
)
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
    cycles: tuple[int, int]  # (least, most) cycles of the instruction itself, branch outcome excluded
    successors: list[tuple[int, int]] = field(default_factory=list)  # (pc, extra cycles on that edge)
    returns: bool = False


@dataclass(frozen=True)
class Bounds:
    best: int
    worst: int
    instructions: int  # distinct instructions reachable from the entry


def decode(read: Callable[[int], int], entry: int,
           call_cost: Callable[[int, int], tuple[int, int]] | None = None, cpu: str = "6510",
           ends: frozenset[int] = frozenset({OPCODE_RTS}), exits: frozenset[int] = frozenset()) -> dict[int, Node]:
    """The instructions reachable from entry. A JSR costs its own cycles plus the callee's best and
    worst (`call_cost(pc, target)`), then continues after it, as the callee's RTS returns there.
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
            nodes[pc] = Node(pc, (0, 0), returns=True)
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
        extra = 0
        if op.page_penalty and (op.mode == "iny" or (op.mode in ("abx", "aby") and operand & 0xFF)):
            extra = PAGE_CROSS_CYCLES
        if cmos and op.mnemonic in ("ADC", "SBC"):
            extra += CMOS_DECIMAL_CYCLES
        node = Node(pc, (op.cycles, op.cycles + extra))
        following = (pc + op.length) & 0xFFFF
        if opcode == OPCODE_JSR:
            best, worst = call_cost(pc, operand)
            node.cycles = (op.cycles + best, op.cycles + worst)
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
            else:
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


def analyse(read: Callable[[int], int], entry: int, loop_bounds: dict[int, int] | None = None,
            name: str = "routine", within: tuple[int, int] | None = None,
            describe: Callable[[int], str] | None = None, cpu: str = "6510", *,
            mocks: dict[int, int] | None = None, interrupt: bool = False, exits: frozenset[int] = frozenset()) -> Bounds:
    """Best and worst cycles from the entry through an RTS over every path the bytes allow.

    Subroutines called with JSR are analysed the same way (their loops bounded by the same
    `loop_bounds`) and their cost is included, as long as they lie in `within` (start, end) when
    given; recursion is an error. `describe(address)` names an address in errors (a label).
    A routine's world (retro.routines.world): `mocks` {JSR target: its cycles through its RTS},
    `interrupt` (the entry is a handler: its RTI ends it), `exits` (reaching one ends it); the
    interrupt sequence's own cycles are the caller's to add."""
    return _analyse(read, entry, dict(loop_bounds or {}), name, within, describe or (lambda a: f"${a:04X}"), {}, (),
                    cpu, dict(mocks or {}), frozenset(exits), interrupt)


def _analyse(read, entry: int, bounds: dict[int, int], name: str, within, describe, done: dict, calling: tuple,
             cpu: str, mocks: dict[int, int] | None = None, exits: frozenset[int] = frozenset(),
             interrupt: bool = False) -> Bounds:
    mocks = mocks or {}
    ends = frozenset({OPCODE_RTS, OPCODE_RTI}) if interrupt else frozenset({OPCODE_RTS})

    def call_cost(pc: int, target: int) -> tuple[int, int]:
        if target in mocks:
            return mocks[target], mocks[target]
        if within is not None and not within[0] <= target < within[1]:
            raise InputError(f"{name}: JSR {describe(target)} at ${pc:04X} calls outside the program "
                             f"(${within[0]:04X}-${within[1] - 1:04X}); its cost is unknown: say what it does and costs "
                             "with a mock ([mocks], docs/specs.md)")
        if target in calling or target == entry:
            raise InputError(f"{name}: JSR {describe(target)} at ${pc:04X} is recursive")
        if target not in done:
            done[target] = _analyse(read, target, bounds, name, within, describe, done, (*calling, entry), cpu, mocks,
                                    exits)
        callee = done[target]
        return callee.best, callee.worst

    nodes = decode(read, entry, call_cost, cpu, ends, exits)
    reached = sorted(pc for pc in nodes if pc in exits)
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
    best: dict = {}
    worst: dict = {}
    # Iterative post-order over the acyclic state graph.
    stack = [(start, False)]
    while stack:
        state, expanded = stack.pop()
        if state in worst:
            continue
        node = nodes[state[0]]
        successors = [(s, extra) for s, extra in ((next_state(state, t), e) for t, e in node.successors) if s is not None]
        if not expanded:
            stack.append((state, True))
            stack.extend((s, False) for s, _ in successors if s not in worst)
            continue
        low, high = node.cycles
        if node.returns:
            best[state], worst[state] = low, high
            continue
        options = [(best[s] + extra, worst[s] + extra) for s, extra in successors if worst.get(s) is not None]
        if not options:
            best[state] = worst[state] = None
            continue
        best[state] = low + min(b for b, _ in options)
        worst[state] = high + max(w for _, w in options)
    if worst[start] is None:
        raise InputError(f"{name}: no path from {describe(entry)} reaches an RTS within the loop bounds")
    return Bounds(best=best[start], worst=worst[start], instructions=len(nodes))
