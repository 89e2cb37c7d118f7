"""The SMT translation (retro.optimize.smt): every translated opcode against the Machine
(retro.cpu.machine) on random states, and equivalence proofs whose answer is known both ways."""

from __future__ import annotations

import random
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import z3

from retro.cpu.disassembly import opcode_table
from retro.cpu.machine import Machine as RealMachine
from retro.cpu.opcodes import DOCUMENTED, MODE_LENGTH
from retro.optimize import smt
from retro.optimize.code import Instruction, Listing, assemble
from retro.optimize.effects import ALL_MEMORY
from retro.routines.spec import load_spec

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "optimize"

FLAG_BITS = {"N": 0x80, "V": 0x40, "D": 0x08, "I": 0x04, "Z": 0x02, "C": 0x01}
EDGES = (0x00, 0x01, 0x09, 0x0F, 0x10, 0x7F, 0x80, 0x99, 0x9A, 0xF0, 0xFF)


def _translated(cpu: str) -> list:
    rows = []
    for opcode, op in sorted(opcode_table(cpu).items()):
        instruction = Instruction(op.mnemonic, op.mode, None if op.mode in ("imp", "acc", "rel") else 0,
                                  "end" if op.mode == "rel" else None)
        if op.kind == DOCUMENTED and smt.supported(instruction, cpu):
            rows.append((cpu, opcode, op.mnemonic, op.mode))
    return rows


ROWS = _translated("6510") + [row for row in _translated("2a03") if row[2] in ("ADC", "SBC")]


def _value(rng: random.Random) -> int:
    return rng.choice(EDGES) if rng.random() < 0.4 else rng.randrange(256)


def _concrete(expression) -> int:
    return z3.simplify(expression).as_long()


def _truth(expression) -> bool:
    return z3.is_true(z3.simplify(expression))


@pytest.mark.parametrize("cpu,opcode,mnemonic,mode", ROWS, ids=[f"{r[0]}-{r[1]:02X}-{r[2]}-{r[3]}" for r in ROWS])
def test_each_translated_opcode_agrees_with_the_machine_on_random_states(cpu, opcode, mnemonic, mode):
    rng = random.Random(opcode * 7 + len(cpu))
    states = 60 if mnemonic in ("ADC", "SBC") else 24 if mnemonic in ("CMP", "CPX", "CPY", "BIT") else 12
    for _ in range(states):
        at = rng.choice((0x02F0, 0x10FD, 0xC000, 0x80FE, rng.randrange(0x0200, 0xF000)))
        operand = rng.choice((rng.randrange(0x10000), 0x00FF, 0x12FF, 0x20F0)) if mode in (
            "abs", "abx", "aby") else rng.choice((0xFF, _value(rng)))
        a, x, y, p = _value(rng), _value(rng), _value(rng), _value(rng) | 0x30
        fill = rng.randrange(256)
        if rng.random() < 0.3:  # an operand equal to a register: the compares' and BIT's edge
            fill = rng.choice((a, x, y))
            if mode == "imm":
                operand = fill
        memory = {k: rng.randrange(256) for k in rng.sample(range(0x10000), 8)}
        if mode in ("inx", "iny"):  # page zero random: the pointers (and their wrap at $FF)
            memory.update((k, rng.randrange(256)) for k in range(0x100))
        if mode == "rel":
            distance = rng.choice((0, 1, 0x7F))
            instruction = Instruction(mnemonic, mode, None, "end")
            body = (instruction,) + (Instruction("NOP", "imp"),) * distance
            fragment = smt.Fragment(body, at, {"end": len(body)}, cpu)
            code = assemble(Listing(at, body, (("end", len(body)),)), cpu)
        else:
            instruction = Instruction(mnemonic, mode, None if mode in ("imp", "acc") else operand & (
                0xFF if MODE_LENGTH[mode] == 2 else 0xFFFF))
            fragment = smt.Fragment((instruction,), at, {}, cpu)
            code = assemble(Listing(at, (instruction,)), cpu)
        for k, b in enumerate(code):
            memory[(at + k) & 0xFFFF] = b
        real = RealMachine(cpu)
        image = real.mpu.memory
        image[:] = [fill] * 0x10000
        for address, value in memory.items():
            image[address] = value
        before = list(image)
        mpu = real.mpu
        mpu.a, mpu.x, mpu.y, mpu.p, mpu.pc = a, x, y, p, at
        began = mpu.processorCycles
        end = at + len(code)
        while mpu.pc != end:
            mpu.step()
        spent = mpu.processorCycles - began
        symbolic_memory = z3.K(z3.BitVecSort(16), smt.byte(fill))
        for address, value in sorted(memory.items()):
            symbolic_memory = z3.Store(symbolic_memory, smt.word(address), smt.byte(value))
        entry = smt.Machine(smt.byte(a), smt.byte(x), smt.byte(y),
                            {n: z3.BoolVal(bool(p & bit)) for n, bit in FLAG_BITS.items()}, symbolic_memory,
                            smt.word(0))
        out = smt.run(fragment, entry)
        where = f"{mnemonic} {mode} operand {operand:#x} at {at:#x}, A={a:#x} X={x:#x} Y={y:#x} P={p:#x}"
        assert (_concrete(out.a), _concrete(out.x), _concrete(out.y)) == (mpu.a, mpu.x, mpu.y), where
        for name, bit in FLAG_BITS.items():
            assert _truth(out.flags[name]) == bool(mpu.p & bit), f"{name}: {where}"
        assert _concrete(out.cycles) == spent, f"cycles: {where}"
        changed = {k for k in range(0x10000) if image[k] != before[k]} if image != before else set()
        changed |= {_concrete(w) for w in out.written}
        for address in changed:
            assert _concrete(z3.Select(out.memory, smt.word(address))) == image[address], f"${address:04X}: {where}"


def test_every_documented_opcode_of_the_search_pool_is_translated():
    names = {row[2] for row in ROWS}
    for name in ("LDA", "STA", "ADC", "SBC", "CMP", "BIT", "ROR", "INC", "DEC", "BCS", "TAX", "CLV", "SED"):
        assert name in names
    modes = {row[3] for row in ROWS}
    assert modes == {"imp", "acc", "imm", "zpg", "zpx", "zpy", "abs", "abx", "aby", "inx", "iny", "rel"}


# ---- proofs whose answer is known ------------------------------------------------------------------

def _i(text: str) -> Instruction:
    """'LDA #$05', 'STA $FB', 'TXA', 'BCS done', 'LDA $1000,X' as an Instruction."""
    name, _, arg = text.partition(" ")
    if not arg:
        return Instruction(name, "acc" if name in ("ASL", "LSR", "ROL", "ROR") else "imp")
    if name.startswith("B") and name != "BIT":
        return Instruction(name, "rel", None, arg)
    if arg.startswith("#"):
        return Instruction(name, "imm", int(arg[2:], 16))
    index = ""
    if "," in arg:
        arg, index = arg.split(",")
    value = int(arg[1:], 16)
    small = value < 0x100 and len(arg) <= 3
    mode = {"": "zpg" if small else "abs", "X": "zpx" if small else "abx", "Y": "zpy" if small else "aby"}[index]
    return Instruction(name, mode, value)


def _fragment(lines: str, at: int = 0xC000, cpu: str = "6510") -> smt.Fragment:
    instructions, labels = [], {}
    for line in filter(None, (part.strip() for part in lines.split("/"))):
        if line.endswith(":"):
            labels[line[:-1]] = len(instructions)
            continue
        instructions.append(_i(line))
    return smt.Fragment(tuple(instructions), at, labels, cpu)


def test_a_transfer_for_a_store_and_load_is_proven_with_the_temporary_dead():
    result = smt.prove_equivalent(_fragment("STX $FB / LDA $FB"), _fragment("TXA"), frozenset({"A", "N", "Z"}))
    assert result.status == "proven", result
    assert result.cycles == (6, 2) and result.no_slower


def test_the_same_pair_is_refuted_when_the_temporary_stays_live():
    result = smt.prove_equivalent(_fragment("STX $FB / LDA $FB"), _fragment("TXA"), frozenset({"A", 0xFB}))
    assert result.status == "refuted"
    assert result.model["memory"][0xFB] != result.model["x"]


def test_the_better_absolute_difference_is_proven_over_every_state_with_decimal_mode_off():
    textbook = _fragment("SEC / SBC $FB / BCS done / EOR #$FF / ADC #$01 / done:")
    better = _fragment("CMP $FB / SBC $FB / BCS done / EOR #$FF / done:")
    proven = smt.prove_equivalent(textbook, better, frozenset({"A"}), smt.Assumptions(flags={"D": False}))
    assert proven.status == "proven", proven
    assert proven.cycles == (11, 10) and proven.no_slower is False  # 10 > 9 when the branch is taken... per path
    free = smt.prove_equivalent(textbook, better, frozenset({"A"}))  # D free: decimal SBC differs
    assert free.status == "refuted" and free.model["D"]


def test_a_wrong_candidate_gets_a_counterexample_that_fails_on_the_machine():
    textbook = _fragment("SEC / SBC $FB / BCS done / EOR #$FF / ADC #$01 / done:")
    wrong = _fragment("SEC / SBC $FB / BCS done / EOR #$FF / done:")  # off by one when it borrowed
    result = smt.prove_equivalent(textbook, wrong, frozenset({"A"}), smt.Assumptions(flags={"D": False}))
    assert result.status == "refuted"
    model = result.model
    outcomes = []
    for fragment in (textbook, wrong):
        body = fragment.instructions + (Instruction("RTS", "imp"),)
        listing = Listing(0xC000, body, tuple((n, k) for n, k in fragment.labels.items()))
        machine = RealMachine("6510")
        for k, b in enumerate(assemble(listing)):
            machine.mpu.memory[0xC000 + k] = b
        p = sum(bit for name, bit in FLAG_BITS.items() if model[name]) | 0x20
        machine.poke(0xFB, [model["memory"].get(0xFB, 0)])
        outcomes.append(machine.call(0xC000, a=model["a"], x=model["x"], y=model["y"], p=p).a)
    assert outcomes[0] != outcomes[1]


def test_flags_left_live_must_match_too():
    # CLC / ADC #1 and SEC / ADC #0 leave the same A and flags: proven; INX-like tricks do not
    same = smt.prove_equivalent(_fragment("CLC / ADC #$01"), _fragment("SEC / ADC #$00"),
                                frozenset({"A", "N", "Z", "C", "V"}))
    assert same.status == "proven"
    differ = smt.prove_equivalent(_fragment("LDA #$00"), _fragment("AND #$00"), frozenset({"A", "N", "Z", "C"}))
    assert differ.status == "proven"
    value = smt.prove_equivalent(_fragment("LDA #$00"), _fragment("EOR $FB"), frozenset({"A"}))
    assert value.status == "refuted"
    carry = smt.prove_equivalent(_fragment("LDA #$00"), _fragment("LDA #$00 / SEC"), frozenset({"A", "C"}))
    assert carry.status == "refuted" and not carry.model["C"]
    assert smt.prove_equivalent(_fragment("LDA #$00"), _fragment("LDA #$00 / SEC"), frozenset({"A"})).status == "proven"


def test_a_table_read_is_proven_only_with_the_tables_bytes_assumed():
    double = {0x1000 + k: (2 * k) & 0xFF for k in range(256)}
    textbook, lookup = _fragment("TXA / ASL"), _fragment("LDA $1000,X")
    assert smt.prove_equivalent(textbook, lookup, frozenset({"A"})).status == "refuted"
    assert smt.prove_equivalent(textbook, lookup, frozenset({"A"}), smt.Assumptions(fixed=double)).status == "proven"


def test_whole_memory_live_compares_every_byte_outside_the_code():
    result = smt.prove_equivalent(_fragment("STA $FB / LDA #$00"), _fragment("LDA #$00"), frozenset({"A", ALL_MEMORY}))
    assert result.status == "refuted"
    assert smt.prove_equivalent(_fragment("STA $FB / STA $FB"), _fragment("STA $FB"),
                                frozenset({ALL_MEMORY})).status == "proven"


def test_an_indexed_store_that_may_reach_the_code_is_not_proven():
    result = smt.prove_equivalent(_fragment("STA $C000,X"), _fragment("STA $C000,X"), frozenset({ALL_MEMORY}),
                                  smt.Assumptions(code_range=(0xC000, 0xC010)))
    assert result.status == "unsupported" and "code" in result.reason


def test_untranslated_instructions_are_unsupported_never_proven():
    pha = smt.Fragment((Instruction("PHA", "imp"),), 0xC000, {}, "6510")
    assert smt.prove_equivalent(pha, pha, frozenset({"A"})).status == "unsupported"
    nop = smt.Fragment((Instruction("NOP", "imp"),), 0xC000, {}, "65c02")
    assert smt.prove_equivalent(nop, nop, frozenset({"A"})).status == "unsupported"
    back = _fragment("top: / DEX / BNE top")
    assert smt.prove_equivalent(back, back, frozenset({"X"})).status == "unsupported"


def test_changed_fragments_finds_the_differing_run():
    old = Listing(0xC000, (_i("STX $FB"), _i("LDA $FB"), _i("CLC"), _i("ADC $1000"), _i("RTS")))
    new = Listing(0xC000, (_i("TXA"), _i("CLC"), _i("ADC $1000"), _i("RTS")))
    assert smt.changed_fragments(old, new) == (0, 2, 1)
    dropped = Listing(0xC000, (_i("STX $FB"), _i("LDA $FB"), _i("ADC $1000"), _i("RTS")))
    assert smt.changed_fragments(old, dropped) == (2, 4, 3)  # an empty side takes its next instruction
    assert smt.changed_fragments(old, old) is None


# ---- in the search: past the sweep's reach ----------------------------------------------------------

def test_changes_past_the_sweep_are_proven_by_z3_and_the_report_says_so(tmp_path):
    from retro.commands.optimize import as_json, optimize as optimize_command
    result = optimize_command(str(EXAMPLES / "sum3.toml"), budget=8, out=str(tmp_path / "out"))
    data = as_json(result)
    assert data["after"]["worst"] < data["before"]["worst"]
    assert data["proof"]["kind"] == "smt" and data["proof"]["space"] == 1 << 24
    assert data["proof"]["smt"] and all(r["status"] == "proven" for r in data["proof"]["smt"])
    assert data["proof"]["check"]["mismatches"] == 0
    bare = as_json(optimize_command(str(EXAMPLES / "sum3.toml"), budget=3, out=str(tmp_path / "bare"), smt=False))
    assert bare["proof"]["kind"] == "sampled" and not bare["proof"]["smt"]


def _roomy_sum3(tmp_path: Path):
    """sum3 with NOPs before its RTS: room for a longer candidate in its block."""
    source = (EXAMPLES / "sum3.s").read_text().replace("        rts\n", "        nop\n" * 24 + "        rts\n", 1)
    (tmp_path / "sum3.s").write_text(source)
    spec = (EXAMPLES / "sum3.toml").read_text().replace('"refs.py:sum3"', f'"{EXAMPLES / "refs.py"}:sum3"')
    (tmp_path / "sum3.toml").write_text(spec)
    return load_spec(tmp_path / "sum3.toml")


def _rare_wrong(routine) -> tuple[Listing, Listing]:
    """sum3 and a candidate that is wrong on one input of 2^24 only (X = $37, b = $42, c = $99)."""
    from retro.optimize.code import read_listing
    old = read_listing(routine.program, routine.entry_address, routine.cpu)
    b, c = routine.program.symbols["b_val"], routine.program.symbols["c_val"]
    body = (_i("TXA"), _i("CLC"), Instruction("ADC", "abs", b), _i("CLC"), Instruction("ADC", "abs", c),
            _i("CPX #$37"), Instruction("BNE", "rel", None, "done"), Instruction("LDY", "abs", b),
            _i("CPY #$42"), Instruction("BNE", "rel", None, "done"), Instruction("LDY", "abs", c),
            _i("CPY #$99"), Instruction("BNE", "rel", None, "done"), _i("LDA #$00"), _i("RTS"))
    new = Listing(old.origin, body, (("done", len(body) - 1), ("sum3", 0)))
    return old, new


def test_a_wrong_candidate_the_cases_miss_is_refuted_and_its_counterexample_joins_the_samples(tmp_path):
    from retro.optimize.optimizer import Outcome, Search
    from retro.optimize.optimizer import Options as SearchOptions
    routine = _roomy_sum3(tmp_path)
    search = Search(routine, SearchOptions(budget=1))
    old, new = _rare_wrong(routine)
    code = assemble(new, routine.cpu)
    outcome = Outcome(routine, old, old, None, None)
    assert search.prover.prove(code, routine.entry_address).passed  # the spec's cases cannot see it
    before = len(search.samples)
    proof = search.proven(code, outcome, old, new)
    assert not proof.passed and proof.smt[0]["status"] == "refuted"
    assert len(search.samples) == before + 1 and outcome.counterexamples == 1
    assert [int(c[-1]) for c in search.samples.columns] == [0x37, 0x42, 0x99]
    assert not search.sample_ok(code)  # the test set now holds the case it fails


def test_a_routine_z3_refutes_in_the_domain_is_refused_though_the_core_passes_it(tmp_path):
    """z3 and the batched core disagree (here: a refutation put in z3's mouth for a right change,
    STX t / LDA t -> TXA, with an entry state in the domain): the change is refused, never admitted
    on the cases alone; the state still joins the samples."""
    from retro.optimize.code import read_listing
    from retro.optimize.formal import Counterexample, Verdict
    from retro.optimize.optimizer import Options as SearchOptions
    from retro.optimize.optimizer import Outcome, Search
    routine = _roomy_sum3(tmp_path)
    search = Search(routine, SearchOptions(budget=1))
    old = read_listing(routine.program, routine.entry_address, routine.cpu)
    new = old.with_window(0, 2, (_i("TXA"),))
    code = assemble(new, routine.cpu)
    witness = Counterexample([0x12, 0x34, 0x56], {"a": 0, "x": 0x12, "y": 0}, 0, {})

    class Disagreeing:
        def prove(self, before, after):
            return Verdict("routine", smt.Result("refuted", model={}), witness)

    search.formal = Disagreeing()
    outcome = Outcome(routine, old, old, None, None)
    before = len(search.samples)
    proof = search.proven(code, outcome, old, new)
    assert search.sample_ok(code)  # the core's run of z3's state passes
    assert not proof.passed and "refused all the same" in proof.note and outcome.failed_proofs == 1
    assert len(search.samples) == before + 1


def test_z3s_counterexample_of_the_whole_routine_fails_on_the_machine(tmp_path):
    """The inputs and entry state z3 gives, run on the Machine: the candidate's A is not the reference's."""
    from retro.optimize.formal import Formal
    routine = _roomy_sum3(tmp_path)
    old, new = _rare_wrong(routine)
    formal = Formal(routine, bytearray(0x10000), sum(i.length for i in old.instructions), frozenset({"A"}), {})
    verdict = formal.prove(old, new)
    assert (verdict.scope, verdict.result.status) == ("routine", "refuted")
    x, b, c = verdict.counterexample.inputs
    machine = RealMachine("6510")
    for k, value in enumerate(assemble(new, routine.cpu)):
        machine.mpu.memory[new.origin + k] = value
    machine.poke(routine.program.symbols["b_val"], [b])
    machine.poke(routine.program.symbols["c_val"], [c])
    registers = verdict.counterexample.registers
    got = machine.call(new.origin, a=registers["a"], x=x, y=registers["y"], p=verdict.counterexample.bits | 0x20).a
    assert got != (x + b + c) & 0xFF and (x, b, c) == (0x37, 0x42, 0x99)


def test_the_fragment_is_proven_when_the_whole_routine_is_out_of_reach():
    """A JSR keeps the whole routine from the translation: the changed fragment is proven alone."""
    from retro.optimize.formal import Formal
    routine = load_spec(EXAMPLES / "sum3.toml")
    old, _ = _rare_wrong(routine)
    jsr = Instruction("JSR", "abs", None, 0xFFD2)
    old = Listing(old.origin, (jsr,) + old.instructions, tuple((n, k + 1 if k else 0) for n, k in old.labels))
    new = old.with_window(1, 3, (_i("TXA"),))
    formal = Formal(routine, bytearray(0x10000), 16, frozenset({"A"}), {})  # the block before b_val
    verdict = formal.prove(old, new)
    assert verdict.scope == "fragment" and verdict.result.status == "proven", verdict.result
    wrong = old.with_window(1, 3, (_i("TYA"),))
    refuted = formal.prove(old, wrong)
    assert refuted.result.status == "refuted" and refuted.counterexample is None  # a state after the JSR
    at_entry = Listing(old.origin, old.instructions[1:] + (jsr,), tuple((n, k - 1 if k else 0) for n, k in old.labels))
    entry_wrong = at_entry.with_window(0, 2, (_i("TYA"),))
    verdict = formal.prove(at_entry, entry_wrong)
    assert (verdict.scope, verdict.result.status) == ("fragment", "refuted")
    x = verdict.counterexample.inputs[0]
    assert verdict.counterexample.registers["y"] != x  # TYA for X: they differ in the entry state z3 gives


def test_the_result_is_smt_only_when_every_change_on_the_way_was():
    from dataclasses import replace as changed
    from retro.optimize.evaluate import Proof
    from retro.optimize.optimizer import Change, Outcome, chained
    proven = Proof("smt", 1 << 24, smt=[{"status": "proven"}])
    sampled = Proof("sampled", 1 << 24)
    outcome = Outcome(None, None, None, sampled, proven, changes=[Change(0, (), (), "window", proven)])
    assert chained(outcome).kind == "smt"
    outcome.changes.insert(0, Change(0, (), (), "window", sampled))
    assert chained(outcome).kind == "sampled"
    outcome.changes[0] = Change(0, (), (), "window", changed(proven))
    assert chained(outcome).kind == "smt" and len(chained(outcome).smt) == 2


def test_z3_proves_and_refutes_changes_of_aabb8_whose_space_no_sweep_reaches():
    """aabb8: 30 instructions, 5 forward branches, 4 RTS, 2^64 inputs. Swapping two independent
    instructions is proven; dropping a CLC is refuted, and the entry state z3 gives makes the
    batched core's run of the candidate miss the reference's answer."""
    from retro.optimize.evaluate import LaneRunner, Prover, answered, outputs_equal
    from retro.optimize.formal import Formal
    from retro.optimize.code import read_listing
    from retro.paths import ASM_DIR
    routine = load_spec(ASM_DIR / "aabb8.toml")
    old = read_listing(routine.program, routine.entry_address, routine.cpu)
    assert [i.mnemonic for i in old.instructions[8:10]] == ["EOR", "CLC"]
    runner = Prover(routine, routine.seed, ()).baseline.runner
    size = sum(i.length for i in old.instructions)
    formal = Formal(routine, runner.call_image, size, frozenset({"C"}), runner.memory_values)
    swapped = old.with_window(8, 10, (old.instructions[9], old.instructions[8]))
    proven = formal.prove(old, swapped)
    assert (proven.scope, proven.result.status) == ("routine", "proven"), proven.result
    dropped = old.with_window(9, 10, ())
    refuted = formal.prove(old, dropped)
    assert (refuted.scope, refuted.result.status) == ("routine", "refuted")
    witness = refuted.counterexample
    columns = [np.asarray([v], dtype=np.int64) for v in witness.inputs]
    expected, counted = answered(routine, columns, runner.memory_values)
    lanes = LaneRunner(routine, routine.seed, ())
    run = lanes.run(assemble(dropped, routine.cpu), routine.entry_address, columns, np.asarray([1 << 40]),
                    {1 << 40: witness})
    assert counted.all() and not outputs_equal(run, expected).all()


def test_a_change_slower_on_one_input_in_2_to_the_16_is_slower_by_z3_though_no_case_shows_it(tmp_path):
    """--no-slower past the sweep: the cases' cycles miss a path taken on X = $37, b = $42 only;
    z3's cycle model of the whole routine does not."""
    from retro.optimize.optimizer import Outcome, Search
    from retro.optimize.optimizer import Options as SearchOptions
    routine = _roomy_sum3(tmp_path)
    b, c = routine.program.symbols["b_val"], routine.program.symbols["c_val"]
    body = (_i("TXA"), _i("CLC"), Instruction("ADC", "abs", b), _i("CLC"), Instruction("ADC", "abs", c),
            _i("CPX #$37"), Instruction("BNE", "rel", None, "done"), Instruction("LDY", "abs", b),
            _i("CPY #$42"), Instruction("BNE", "rel", None, "done"))
    old = Listing(routine.entry_address, body + (_i("RTS"),), (("done", len(body)), ("sum3", 0)))
    new = Listing(routine.entry_address, body + (_i("NOP"), _i("RTS")), (("done", len(body) + 1), ("sum3", 0)))
    search = Search(routine, SearchOptions(budget=1))
    search.prover.reference_cycles = search.prover.prove(assemble(old, routine.cpu), routine.entry_address).per_case
    outcome = Outcome(routine, old, old, None, None)
    cases_only = search.prover.prove(assemble(new, routine.cpu), routine.entry_address)
    assert cases_only.passed and not cases_only.slower
    proof = search.proven(assemble(new, routine.cpu), outcome, old, new)
    assert proof.kind == "smt" and proof.slower and proof.smt[0]["no_slower"] is False


def test_z3_proves_on_the_specs_domain_not_past_it(tmp_path):
    """sum3 with `where = "a <= 100"`: a candidate wrong only for X > 200 is proven (the check never
    runs such a case); without the domain it is refuted with X > 200."""
    from retro.optimize.formal import Formal
    routine = _roomy_sum3(tmp_path)
    old, _ = _rare_wrong(routine)
    b, c = routine.program.symbols["b_val"], routine.program.symbols["c_val"]
    body = (_i("TXA"), _i("CLC"), Instruction("ADC", "abs", b), _i("CLC"), Instruction("ADC", "abs", c),
            _i("CPX #$C8"), Instruction("BCC", "rel", None, "done"), _i("LDA #$00"), _i("RTS"))
    new = Listing(old.origin, body, (("done", len(body) - 1), ("sum3", 0)))
    size = sum(i.length for i in old.instructions)
    anywhere = Formal(routine, bytearray(0x10000), size, frozenset({"A"}), {}).prove(old, new)
    assert anywhere.result.status == "refuted" and anywhere.counterexample.inputs[0] >= 0xC8
    spec = tmp_path / "sum3.toml"
    spec.write_text(spec.read_text() + '\n[cases]\nwhere = "a <= 100"\n')
    narrowed = load_spec(spec)
    inside = Formal(narrowed, bytearray(0x10000), size, frozenset({"A"}), {}).prove(old, new)
    assert inside.result.status == "proven", inside.result


def test_a_forward_jmp_is_an_edge_z3_follows_with_its_three_cycles():
    """aabb8_jmp's `BCC + / JMP _b_left / +:` made `BCS _b_left` (the flow rewrite) is proven on the
    whole routine, its worst case 36 -> 34 cycles as `retro check` measures them (docs/optimize.md:
    aabb8 36 before, 34 after); the JMP sent to the wrong block is refuted; a JMP back stays
    unsupported."""
    from retro.optimize.code import read_listing
    from retro.optimize.evaluate import Prover
    from retro.optimize.flow import rewrites
    from retro.optimize.formal import Formal
    routine = load_spec(Path(__file__).resolve().parent / "wasteful" / "aabb8_jmp.toml")
    old = read_listing(routine.program, routine.entry_address, routine.cpu)
    runner = Prover(routine, routine.seed, ()).baseline.runner
    formal = Formal(routine, runner.call_image, sum(i.length for i in old.instructions), frozenset({"C"}),
                    runner.memory_values)
    new = dict(rewrites(old))["a branch over a JMP inverted"]
    assert [i.mnemonic for i in new.instructions[:2]] == ["CMP", "BCS"]
    proven = formal.prove(old, new)
    assert (proven.scope, proven.result.status) == ("routine", "proven"), proven.result
    assert proven.result.record()["worst_cycles"] == [36, 34] and proven.result.no_slower
    jump = old.instructions[2]
    wrong = old.with_window(2, 3, (replace(jump, target="_miss"),))
    refuted = formal.prove(old, wrong)
    assert (refuted.scope, refuted.result.status) == ("routine", "refuted")
    back = Listing(0xC000, (Instruction("LDA", "imm", 1), Instruction("JMP", "abs", target="top"),
                            Instruction("RTS", "imp")), (("top", 0),))
    with pytest.raises(smt.Unsupported):
        smt.run(smt.Fragment(back.instructions, 0xC000, dict(back.labels), "6510", returns=True),
                smt.free_machine(z3.Array("m", z3.BitVecSort(16), z3.BitVecSort(8))))
