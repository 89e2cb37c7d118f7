"""Tables as a resource (retro.optimize.tables, `retro optimize --tables`): the table-lookup spec
of docs/optimize.md, the table's bytes counted, and the errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from retro.cli import main as cli_main
from retro.commands.optimize import as_json, optimize as optimize_command
from retro.errors import InputError
from retro.optimize.code import Instruction, Listing
from retro.optimize.tables import Table, table_bytes, table_pool

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "optimize"
SPEC = str(EXAMPLES / "times3.toml")
TABLE = 0xC100


def _reads_table(source_lines) -> bool:
    return any("times3_table" in line for line in source_lines if not line.startswith((".alias", "times3_table =")))


def test_the_lookup_is_found_when_the_table_is_allowed_and_its_bytes_are_counted(tmp_path):
    data = as_json(optimize_command(SPEC, budget=10, tables=("times3",), out=str(tmp_path / "t")))
    assert (data["before"]["worst"], data["before"]["bytes"]) == (16, 7)  # STA t / ASL / CLC / ADC t / RTS
    assert data["after"]["worst"] == 12  # TAX (or TAY) / LDA times3_table,X / RTS: 2 + 4 + 6
    assert data["after"]["table_bytes"] == 256 and data["after"]["bytes"] == 5 + 256
    assert data["proof"]["kind"] == "exhaustive" and data["proof"]["check"]["mismatches"] == 0
    body = [line.split(";")[0].strip().lower() for line in data["source"].splitlines()]
    assert any(line.startswith("lda times3_table,") for line in body), data["source"]


def test_without_the_table_no_candidate_reads_it(tmp_path):
    data = as_json(optimize_command(SPEC, budget=6, out=str(tmp_path / "t")))
    assert data["after"]["table_bytes"] == 0 and data["after"]["worst"] > 12
    assert "times3_table" not in data["source"].lower().replace(".alias times3_table", "")


def test_a_table_does_not_pay_for_itself_in_bytes(tmp_path):
    data = as_json(optimize_command(SPEC, budget=6, tables=("times3",), objective="bytes", out=str(tmp_path / "t")))
    assert data["after"]["table_bytes"] == 0 and data["after"]["bytes"] <= 7


def test_an_unknown_table_is_one_line_exit_2(tmp_path, capsys):
    wanted = r"--tables: 'squares' is not a \[memory\] block of .*times3.toml \(its blocks: times3\)"
    with pytest.raises(InputError, match=wanted):
        optimize_command(SPEC, budget=1, tables=("squares",), out=str(tmp_path / "t"))
    assert cli_main(["optimize", SPEC, "--tables", "squares", "--budget", "1", "--out", str(tmp_path / "u")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--tables" in err[0]


def test_the_pool_reads_each_table_with_either_index_and_sizes_count_each_table_once():
    tables = (Table("t", TABLE, 256), Table("z", 0x80, 16))
    pool = table_pool("6510", tables)
    assert Instruction("LDA", "abx", TABLE) in pool and Instruction("LDA", "aby", TABLE) in pool
    assert Instruction("LDX", "aby", TABLE) in pool and Instruction("LDY", "abx", TABLE) in pool
    assert Instruction("LDA", "zpx", 0x80) in pool and Instruction("LDX", "zpy", 0x80) in pool
    assert Instruction("LDA", "aby", 0x80) in pool  # no LDA zp,Y: the absolute form reads the same bytes
    twice = Listing(0xC000, (Instruction("LDA", "abx", TABLE), Instruction("ADC", "aby", TABLE + 5),
                             Instruction("RTS", "imp")))
    assert table_bytes(twice, tables) == 256


def test_z3_proves_the_lookup_with_the_generated_tables_bytes_and_refutes_a_wrong_table_entry():
    """The whole routine from its entry, the [memory] block (made by a generator) assumed as loaded:
    the lookup is proven; a lookup one byte past the table is not."""
    from retro.optimize.code import read_listing
    from retro.optimize.evaluate import Prover
    from retro.optimize.formal import Formal
    from retro.routines.spec import load_spec
    routine = load_spec(SPEC)
    old = read_listing(routine.program, routine.entry_address, routine.cpu)
    runner = Prover(routine, routine.seed, ()).baseline.runner
    formal = Formal(routine, runner.call_image, 7, frozenset({"A"}), runner.memory_values)
    lookup = old.with_window(0, 4, (Instruction("TAX", "imp"), Instruction("LDA", "abx", TABLE)))
    verdict = formal.prove(old, lookup)
    assert (verdict.scope, verdict.result.status) == ("routine", "proven"), verdict.result
    shifted = old.with_window(0, 4, (Instruction("TAX", "imp"), Instruction("LDA", "abx", TABLE + 1)))
    wrong = formal.prove(old, shifted)
    assert wrong.result.status == "refuted" and wrong.counterexample is not None
    a = wrong.counterexample.inputs[0]
    assert runner.memory_values["times3"][(a + 1) % 256] != (3 * a) & 0xFF or a == 255
