"""The routine's world (retro.routines.world, docs/specs.md "The routine's world"): mocks, scripted
hardware, interrupt-handler entry, named exits, chip overlaps. Every rule is checked on both engines
where both run it, against numbers worked out by hand from the datasheet cycle counts."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from retro.errors import InputError, RunError
from retro.routines.runner import RoutineRunner
from retro.testing import check, spec_from_dict

ENGINES = ("scalar", "batch")
REPO = Path(__file__).resolve().parents[2]


def build(tmp_path: Path, source: str, doc: dict, name: str = "spec"):
    """A spec around an Ophis source (its first line `.org $c000`) given as text."""
    (tmp_path / "r.s").write_text("        .org $c000\n" + source)
    full = {**doc, "program": {"file": "r.s", "entry": "start", **doc.get("program", {})}}
    return spec_from_dict(full, base=tmp_path, name=name)


def run_both(routine, case: tuple) -> list[tuple[tuple, int]]:
    """(outputs, cycles) of one case on Machine and on the batched core."""
    runner = RoutineRunner(routine)
    scalar = runner.run(case)
    columns = [np.asarray([v]) for v in case]
    outcome = runner.run_batch(columns)
    assert not outcome.error.any(), outcome.error
    batch = (tuple(int(o[0]) if o.ndim == 1 else tuple(o[0].tolist()) for o in outcome.outputs), int(outcome.cycles[0]))
    return [scalar, batch]


# ---- interrupt handlers ---------------------------------------------------------------------------

HANDLER = """
start:  php             ; P as the handler sees it
        pla
        sta $fb
        rti
"""


@pytest.mark.parametrize("kind", ["irq", "nmi"])
def test_a_handler_is_entered_with_seven_cycles_and_i_set_and_ends_at_its_rti(tmp_path, kind):
    (tmp_path / "ref.py").write_text("def f(c): return {}\n")
    routine = build(tmp_path, HANDLER, {
        "program": {"interrupt": kind}, "inputs": {"c": "C"},
        "outputs": {"inside": "$fb", "i_after": "I", "c_after": "C"}, "reference": {"function": "ref.py:f"}})
    for outputs, cycles in run_both(routine, (1,)):
        inside, i_after, c_after = outputs
        # 7 (the interrupt sequence) + PHP 3 + PLA 4 + STA zp 3 + RTI 6
        assert cycles == 7 + 3 + 4 + 3 + 6
        assert inside & 0x04, "I is set inside the handler"
        assert c_after == 1, "RTI restores the pushed P"
        # an IRQ is taken only with I clear: its pushed P has I clear; an NMI's keeps the entry's (set)
        assert i_after == (0 if kind == "irq" else 1)


def test_the_static_bounds_of_a_handler_count_the_entry_and_end_at_rti(tmp_path):
    (tmp_path / "ref.py").write_text("def f(c): return {'inside': 0x34 | c}  # PHP: I, bit 5 and B (pushed copies) set\n")
    routine = build(tmp_path, HANDLER, {"program": {"interrupt": "irq"}, "inputs": {"c": "C"},
                                         "outputs": {"inside": "$fb"}, "reference": {"function": "ref.py:f"},
                                         # P is pushed whole: the other flags are the caller's (stated)
                                         "entry": {"z": 0, "d": 0, "v": 0, "n": 0}})
    for engine in ENGINES:
        report = check(routine, engine=engine)
        assert (report.static.best, report.static.worst) == (23, 23)
        assert report.totals.cycles_min == report.totals.cycles_max == 23
        assert not report.mismatches, report.totals.examples


def test_without_interrupt_an_rti_is_refused_by_the_static_analysis(tmp_path):
    (tmp_path / "ref.py").write_text("def f(c): return 0\n")
    routine = build(tmp_path, HANDLER, {"inputs": {"c": "C"}, "outputs": {"inside": "$fb"},
                                         "reference": {"function": "ref.py:f"}})
    with pytest.raises(InputError, match="RTI is not supported"):
        check(routine, engine="scalar")


# ---- exits -----------------------------------------------------------------------------------------

EXIT = """
start:  lda $fb
        beq away
        sta $fc
        jmp done        ; the named exit: the call ends here
away:   jmp $ea31       ; a second exit, outside the program
done:   brk             ; never run: reaching done ends the call
"""


@pytest.mark.parametrize("value, cycles", [(5, 3 + 2 + 3 + 3), (0, 3 + 3 + 3)])
def test_a_jmp_to_an_exit_ends_the_call_with_the_jmp_counted(tmp_path, value, cycles):
    (tmp_path / "ref.py").write_text("def f(v): return v\n")
    routine = build(tmp_path, EXIT, {"program": {"exit": ["done", "$EA31"]}, "inputs": {"v": "$fb"},
                                      "outputs": {"w": "$fc"}, "reference": {"function": "ref.py:f"}})
    for outputs, spent in run_both(routine, (value,)):
        assert spent == cycles
        assert outputs == (value,)


def test_exits_bound_the_static_analysis_and_the_check_holds(tmp_path):
    # v = 0 leaves by the second exit before the store: $fc keeps what it held (an input, so stated)
    (tmp_path / "ref.py").write_text("def f(v, held): return v if v else held\n")
    routine = build(tmp_path, EXIT, {"program": {"exit": ["done", "$EA31"]}, "inputs": {"v": "$fb", "held": "$fc"},
                                      "outputs": {"w": "$fc"}, "reference": {"function": "ref.py:f"}})
    report = check(routine, engine="batch")
    assert (report.static.best, report.static.worst) == (9, 11)
    assert not report.mismatches, report.totals.examples


# ---- mocks -----------------------------------------------------------------------------------------

CALLER = """
start:  lda $fb
        ldx #9
        jsr $e000       ; a mock: returns A = 7, C set, X kept, writes $fd
        sta $fc
        rts
"""


def mock_spec(tmp_path, mock: dict, reference: str, outputs=None):
    (tmp_path / "ref.py").write_text(reference)
    return build(tmp_path, CALLER, {"mocks": {"helper": {"at": "$E000", **mock}}, "inputs": {"v": "$fb"},
                                     "outputs": outputs or {"got": "$fc", "carry": "C", "x": "X", "wrote": "$fd",
                                                            "calls": {"calls": "helper"}},
                                     "reference": {"function": "ref.py:f"}})


def test_a_mock_returns_its_registers_flags_and_bytes_and_its_cycles_are_counted(tmp_path):
    routine = mock_spec(tmp_path, {"cycles": 40, "A": 7, "C": 1, "writes": {"$fd": "$55"}}, "def f(v): return {}\n")
    for outputs, cycles in run_both(routine, (3,)):
        assert outputs == (7, 1, 9, 0x55, 1)
        # LDA zp 3, LDX # 2, JSR 6, the mock's 40 (through its RTS), STA zp 3, RTS 6
        assert cycles == 3 + 2 + 6 + 40 + 3 + 6


def test_the_reference_takes_the_calls_with_their_arguments(tmp_path):
    reference = ("def f(v, helper):\n"
                 "    assert helper == [{'A': v, 'X': 9}], helper\n"
                 "    return {'got': 7, 'carry': 1, 'x': 9, 'wrote': 0x55, 'calls': len(helper)}\n")
    routine = mock_spec(tmp_path, {"cycles": 40, "A": 7, "C": 1, "writes": {"$fd": "$55"}, "args": ["A", "X"]},
                        reference)
    assert routine.world.recorded == {"helper"}
    for engine in ENGINES:
        report = check(routine, engine=engine, random=300)
        assert not report.mismatches, report.totals.examples
        assert (report.static.best, report.static.worst) == (60, 60)
        assert report.totals.cycles_max == 60


def test_a_wrong_call_count_is_a_mismatch(tmp_path):
    routine = mock_spec(tmp_path, {"cycles": 40}, "def f(v): return {'got': v, 'carry': 0, 'x': 9, 'wrote': 0, "
                                                  "'calls': 2}\n")
    for engine in ENGINES:
        report = check(routine, engine=engine, random=100)
        assert report.totals.result_mismatches == report.totals.cases


def test_a_function_mock_runs_on_both_engines_with_the_same_answers(tmp_path):
    (tmp_path / "mocks.py").write_text("def helper(a, count, memory, cycle):\n"
                                       "    assert cycle == 3 + 2 + 6, cycle  # cycles before the mock: LDA, LDX, JSR\n"
                                       "    return {'A': (a + count + memory[0xfb]) & 0xff, 'C': 0, 'writes': {0xfd: a}}\n")
    routine = mock_spec(tmp_path, {"cycles": 12, "function": "mocks.py:helper"},
                        "def f(v): return {'got': (2 * v + 1) & 0xff, 'carry': 0, 'x': 9, 'wrote': v, 'calls': 1}\n")
    assert routine.world.batch_refusal() is None
    for engine in ENGINES:
        report = check(routine, engine=engine, random=300)
        assert report.engine == engine and not report.engine_note
        assert not report.mismatches, report.totals.examples
        assert report.totals.cycles_max == 3 + 2 + 6 + 12 + 3 + 6


def test_a_hardware_function_runs_on_machine_and_the_report_says_why(tmp_path):
    (tmp_path / "hw.py").write_text("def raster(count): return count\n")
    (tmp_path / "ref.py").write_text("def f(v): return {'r': [0, 1, 2]}\n")
    routine = build(tmp_path, POLL, {"hardware": {"raster": {"at": "$D012", "function": "hw.py:raster"}},
                                     "inputs": {"v": "$fe"}, "outputs": {"r": {"at": "$fb", "size": 3, "table": True}},
                                     "reference": {"function": "ref.py:f"}})
    report = check(routine, engine="batch", random=100)
    assert report.engine == "scalar"
    assert report.engine_note == ("Machine ran the calls: hardware.raster.function is a Python function, run per read "
                                  "on Machine")
    assert not report.mismatches, report.totals.examples


def test_a_function_mock_that_answers_nonsense_is_one_line_naming_it(tmp_path):
    (tmp_path / "mocks.py").write_text("def helper(a):\n    return {'A': 300}\n")
    routine = mock_spec(tmp_path, {"cycles": 12, "function": "mocks.py:helper"}, "def f(v): return {}\n")
    with pytest.raises(InputError, match=r"mocks.helper.function returned 300 \(call 1\): expected a whole number 0..255"):
        RoutineRunner(routine).run((1,))


def test_a_jsr_to_nowhere_names_the_address_and_suggests_a_mock(tmp_path):
    (tmp_path / "ref.py").write_text("def f(v): return v\n")
    routine = build(tmp_path, CALLER, {"inputs": {"v": "$fb"}, "outputs": {"got": "$fc"},
                                        "reference": {"function": "ref.py:f"}})
    with pytest.raises(RunError, match=r"JSR \$E000 at \$C004 calls an address where no code is .*\[mocks\]"):
        RoutineRunner(routine).run((1,))


# ---- hardware ----------------------------------------------------------------------------------------

POLL = """
start:  lda $d012
        sta $fb
        lda $d012
        sta $fc
        lda $d012
        sta $fd
        lda #3
        sta $d020
        lda #4
        sta $d020
        rts
"""


def test_scripted_reads_come_in_order_with_the_last_held_and_writes_are_recorded(tmp_path):
    (tmp_path / "ref.py").write_text("def f(): return {}\n")
    routine = build(tmp_path, POLL, {
        "hardware": {"raster": {"at": "$D012", "reads": [10, 20]}, "border": {"at": "$D020"}},
        "inputs": {}, "outputs": {"r": {"at": "$fb", "size": 3, "table": True}, "colours": {"writes": "border", "size": 3},
                                  "stores": {"writes": "border"}, "last": "$D020"},
        "reference": {"function": "ref.py:f"}, "cases": {"random": 1}})
    runner = RoutineRunner(routine)
    outputs, cycles = runner.run(())
    assert outputs == ((10, 20, 20), (3, 4, 0), 2, 4)
    assert cycles == 3 * (4 + 3) + 2 * (2 + 4) + 6


def test_a_read_function_gets_the_read_count_and_the_cycle(tmp_path):
    (tmp_path / "hw.py").write_text("def raster(count, cycle): return (count * 16 + cycle) & 0xff\n")
    (tmp_path / "ref.py").write_text("def f(): return {}\n")
    routine = build(tmp_path, POLL, {"hardware": {"raster": {"at": "$D012", "function": "hw.py:raster"}},
                                     "inputs": {}, "outputs": {"r": {"at": "$fb", "size": 3, "table": True}},
                                     "reference": {"function": "ref.py:f"}, "cases": {"random": 1}})
    outputs, _ = RoutineRunner(routine).run(())
    # LDA abs reads in its 4th cycle (cycle 3 counted from 0); each LDA + STA zp pair takes 7 cycles
    assert outputs == ((3, 16 + 10, 32 + 17),)


# ---- a scene's chips ----------------------------------------------------------------------------------

def test_an_input_on_a_chip_register_of_the_scene_is_an_error_naming_both(tmp_path):
    (tmp_path / "ref.py").write_text("def f(v): return v\n")
    (tmp_path / "r.s").write_text("        .org $c000\nstart:  lda $d01e\n        rts\n")
    (tmp_path / "spec.toml").write_text('[program]\nfile = "r.s"\nentry = "start"\n[inputs]\nv = "$d01e"\n'
                                        '[outputs]\nw = "A"\n[reference]\nfunction = "ref.py:f"\n')
    done = subprocess.run([sys.executable, "-m", "retro", "check", str(tmp_path / "spec.toml"), "--scene",
                           str(REPO / "examples/vic_two_balls.toml")], capture_output=True, text=True,
                          env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"})
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "inputs.v.at: $D01E is a register of the VIC-II ($D000-$D3FF) of the scene" in lines[0]
    assert "vic_two_balls.toml" in lines[0]


# ---- bad values of every new key ----------------------------------------------------------------------

BAD = [
    ({"program": {"interrupt": "brk"}}, "program.interrupt"),
    ({"program": {"interrupt": 1}}, "program.interrupt"),
    ({"program": {"exit": True}}, "program.exit"),
    ({"program": {"exit": "nowhere"}}, "program.exit"),
    ({"mocks": {"m": {"at": "$E000"}}}, "mocks.m.cycles"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 0}}}, "mocks.m.cycles"),
    ({"mocks": {"m": {"at": "start", "cycles": 5}}}, "mocks.m.at"),
    ({"mocks": {"m": {"at": "A", "cycles": 5}}}, "mocks.m.at"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "A": 256}}}, "mocks.m.A"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "C": 2}}}, "mocks.m.C"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "writes": {"$fd": 999}}}}, "mocks.m.writes.$fd"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "writes": [1]}}}, "mocks.m.writes"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "args": "A"}}}, "mocks.m.args"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "args": ["Q"]}}}, "mocks.m.args[0]"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "function": "nope"}}}, "mocks.m.function"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "A": 1, "function": "ref.py:f"}}}, "mocks.m.function"),
    ({"mocks": {"m": {"at": "$E000", "cycles": 5, "colour": 1}}}, "mocks.m.colour"),
    ({"mocks": {"m": 5}}, "mocks.m"),
    ({"mocks": {"v": {"at": "$E000", "cycles": 5}}}, "mocks.v"),
    ({"hardware": {"h": {"at": "$00fb"}}}, "hardware.h.at"),
    ({"hardware": {"h": {"at": "$D012", "reads": []}}}, "hardware.h.reads"),
    ({"hardware": {"h": {"at": "$D012", "reads": [300]}}}, "hardware.h.reads[0]"),
    ({"hardware": {"h": {"at": "$D012", "reads": "lots"}}}, "hardware.h.reads"),
    ({"hardware": {"h": {"at": "$D012", "reads": [1], "function": "ref.py:f"}}}, "hardware.h"),
    ({"hardware": {"h": {"at": "$D012", "function": "ref.py:f"}}}, "hardware.h.function"),
    ({"hardware": {"h": {"at": "$D012"}}, "mocks": {"m": {"at": "$D012", "cycles": 5}}}, "hardware.h.at"),
    ({"hardware": {"h": {"at": "$D012"}}, "inputs": {"v": "$D012"}}, "inputs.v.at"),
    ({"hardware": {"h": {"at": "$D012"}}, "memory": {"b": {"at": "$D000", "fill": 0, "size": 32}}}, "memory.b.at"),
    ({"outputs": {"o": {"calls": "missing"}}}, "outputs.o.calls"),
    ({"outputs": {"o": {"writes": "missing"}}}, "outputs.o.writes"),
    ({"outputs": {"o": {"writes": "h", "size": 0}}, "hardware": {"h": {"at": "$D012"}}}, "outputs.o.size"),
    ({"outputs": {"o": {"calls": "m", "size": 2}}, "mocks": {"m": {"at": "$E000", "cycles": 5}}}, "outputs.o.size"),
    ({"outputs": {"o": {"calls": "m", "writes": "h"}}, "mocks": {"m": {"at": "$E000", "cycles": 5}}}, "outputs.o"),
]


@pytest.mark.parametrize("doc, key", BAD, ids=[key for _, key in BAD])
def test_a_bad_value_of_a_new_key_is_one_line_naming_the_file_and_the_key(tmp_path, doc, key):
    (tmp_path / "ref.py").write_text("def f(v): return 0\n")
    base = {"inputs": {"v": "$fb"}, "outputs": {"w": "$fc"}, "reference": {"function": "ref.py:f"}}
    outputs = {**base["outputs"], **doc.pop("outputs", {})}
    doc = {"inputs": base["inputs"], **doc}
    with pytest.raises(InputError) as raised:
        build(tmp_path, "start:  rts\n", {**base, **doc, "outputs": outputs})
    message = str(raised.value)
    assert "\n" not in message
    assert message.startswith(f"spec (built in Python): {key}:"), message


def test_a_bad_key_from_the_cli_exits_2_with_one_line(tmp_path):
    (tmp_path / "r.s").write_text("        .org $c000\nstart:  rts\n")
    (tmp_path / "ref.py").write_text("def f(v): return 0\n")
    (tmp_path / "spec.toml").write_text('[program]\nfile = "r.s"\nentry = "start"\ninterrupt = "reset"\n'
                                        '[inputs]\nv = "$fb"\n[outputs]\nw = "A"\n[reference]\nfunction = "ref.py:f"\n')
    done = subprocess.run([sys.executable, "-m", "retro", "check", str(tmp_path / "spec.toml")], capture_output=True,
                          text=True, env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"})
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "spec.toml: program.interrupt:" in done.stderr


# ---- more of the same rules, in other settings ----------------------------------------------------------

def test_a_65c02_handler_is_entered_with_d_clear(tmp_path):
    (tmp_path / "ref.py").write_text("def f(d): return {}\n")
    routine = build(tmp_path, HANDLER, {"program": {"interrupt": "nmi", "cpu": "65c02"}, "inputs": {"d": "D"},
                                         "outputs": {"inside": "$fb", "d_after": "D"}, "reference": {"function": "ref.py:f"}})
    for (inside, d_after), cycles in run_both(routine, (1,)):
        assert not inside & 0x08, "the 65C02's interrupt sequence clears D"
        assert d_after == 1, "RTI restores the pushed D"
        assert cycles == 7 + 3 + 4 + 3 + 6


def test_init_may_call_a_mock_and_a_reference_on_arrays_takes_the_calls(tmp_path):
    source = CALLER + "setup:  jsr $e000\n        sta $fe\n        rts\n"
    (tmp_path / "ref.py").write_text(
        "import numpy as np\n"
        "def f(v, helper):\n"
        "    assert len(helper) == len(v) and all(calls == [{'A': int(a)}] for calls, a in zip(helper, v))\n"
        "    return {'got': np.full(len(v), 7), 'calls': np.ones(len(v), dtype=int), 'seen': np.full(len(v), 7)}\n")
    routine = build(tmp_path, source, {"program": {"init": "setup"},
                                       "mocks": {"helper": {"at": "$E000", "cycles": 10, "A": 7, "args": ["A"]}},
                                       "inputs": {"v": "$fb"},
                                       "outputs": {"got": "$fc", "calls": {"calls": "helper"}, "seen": "$fe"},
                                       "reference": {"function": "ref.py:f", "arrays": True}})
    for engine in ENGINES:
        report = check(routine, engine=engine, random=500)
        assert not report.mismatches, report.totals.examples


def test_rows_state_world_outputs(tmp_path):
    routine = build(tmp_path, POLL, {
        "hardware": {"raster": {"at": "$D012", "reads": [10, 20]}, "border": {"at": "$D020"}},
        "inputs": {}, "outputs": {"colours": {"writes": "border", "size": 2}, "stores": {"writes": "border"}},
        "rows": [{"colours": [3, 4], "stores": 2, "cycles": 39}, {"colours": [3, 5], "note": "wrong"}]})
    report = check(routine)
    assert [o.row.key for o in report.rows.failing] == ["rows[1]"]


def test_scripted_reads_and_recorded_writes_agree_on_both_engines(tmp_path):
    source = """
start:  ldx $fb
loop:   lda $d012       ; wait until the raster reads 40 or more (the script climbs by 10)
        cmp #40
        bcc loop
        stx $d020
        inx
        txa
        sta $d020,y     ; Y = 0: the same register through an indexed store
        rts
"""
    (tmp_path / "ref.py").write_text("def f(v, y): return {'colours': [v, (v + 1) & 0xff, 0], 'stores': 2}\n")
    routine = build(tmp_path, source, {
        "hardware": {"raster": {"at": "$D012", "reads": [0, 10, 20, 30, 40, 50]}, "border": {"at": "$D020"}},
        "inputs": {"v": "$fb", "y": {"at": "Y", "values": [0]}},
        "outputs": {"colours": {"writes": "border", "size": 3}, "stores": {"writes": "border"}},
        "reference": {"function": "ref.py:f"}, "cycles": {"loops": {"loop": 6}}})
    assert routine.world.batch_refusal() is None
    for engine in ENGINES:
        report = check(routine, engine=engine, random=300)
        assert report.engine == engine and not report.engine_note
        assert not report.mismatches, report.totals.examples
        # LDX zp 3, five polls (LDA abs 4, CMP # 2, BCC 3 taken / 2 the last), STX abs 4, INX 2, TXA 2,
        # STA abs,Y 5, RTS 6
        assert report.totals.cycles_min == report.totals.cycles_max == 3 + 5 * (4 + 2 + 3) - 1 + 4 + 2 + 2 + 5 + 6


def test_an_nmos_read_modify_write_of_hardware_runs_on_machine(tmp_path):
    (tmp_path / "ref.py").write_text("def f(): return {}\n")
    routine = build(tmp_path, "start:  inc $d020\n        rts\n",
                    {"hardware": {"border": {"at": "$D020"}}, "inputs": {},
                     "outputs": {"colours": {"writes": "border", "size": 2}}, "rows": [{"colours": [0, 1]}]})
    assert "read-modified-written at $C000" in routine.world.batch_refusal()
    report = check(routine, engine="batch")
    assert report.engine == "scalar" and not report.mismatches  # the NMOS double write: the old value, then the new


def test_a_jsr_to_nowhere_stops_the_check_on_the_batched_core_too(tmp_path):
    (tmp_path / "ref.py").write_text("def f(v): return v\n")
    routine = build(tmp_path, CALLER, {"inputs": {"v": "$fb"}, "outputs": {"got": "$fc"},
                                        "reference": {"function": "ref.py:f"}, "cycles": {"static": False}})
    report = check(routine, engine="batch", random=100)
    assert report.totals.run_errors == 1
    assert "JSR $E000 at $C004 calls an address where no code is" in report.totals.failure.message


@pytest.mark.parametrize("cpu", ["2a03", "65c02"])
def test_mocks_and_exits_work_on_every_cpu(tmp_path, cpu):
    (tmp_path / "ref.py").write_text("def f(v): return {}\n")
    routine = build(tmp_path, CALLER, {"program": {"cpu": cpu}, "mocks": {"helper": {"at": "$E000", "cycles": 40,
                                                                                    "A": 7, "C": 1}},
                                        "inputs": {"v": "$fb"}, "outputs": {"got": "$fc", "carry": "C"},
                                        "reference": {"function": "ref.py:f"}})
    for outputs, cycles in run_both(routine, (3,)):
        assert outputs == (7, 1)
        assert cycles == 3 + 2 + 6 + 40 + 3 + 6


def test_an_exit_reached_inside_a_subroutine_is_said_not_bounded(tmp_path):
    (tmp_path / "ref.py").write_text("def f(v): return v\n")
    source = "start:  jsr sub\n        rts\nsub:    lda $fb\n        sta $fc\n        jmp done\ndone:   rts\n"
    routine = build(tmp_path, source, {"program": {"exit": "done"}, "inputs": {"v": "$fb"}, "outputs": {"w": "$fc"},
                                       "reference": {"function": "ref.py:f"}})
    with pytest.raises(InputError, match=r"the subroutine at \$C004 \(sub\) reaches the exit \$C00B \(done\)"):
        check(routine, engine="scalar", random=10)
    routine = build(tmp_path, source, {"program": {"exit": "done"}, "inputs": {"v": "$fb"}, "outputs": {"w": "$fc"},
                                       "reference": {"function": "ref.py:f"}, "cycles": {"static": False}},
                    name="unbounded")
    for engine in ENGINES:  # the run itself ends at the exit: JSR 6, LDA 3, STA 3, JMP 3
        report = check(routine, engine=engine, random=100)
        assert not report.mismatches and report.totals.cycles_max == 15
