"""`retro run` of a program with --trace (registers, flags, memory read and written, the beam) as text
or JSON lines, bounded; and --watch (reads, writes, execution of an address or range, with a value)."""

from __future__ import annotations

import json

import pytest
from test_c64_run import prg, raster_irq_program

from retro.cli import main

HANDLER = 0x080D + 30  # raster_irq_program's handler: INC $C000 / LSR $D019 / JMP $EA81


def run(*args, capsys):
    code = main(["run", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_trace_has_registers_writes_and_the_beam(tmp_path, capsys):
    path = prg(tmp_path, raster_irq_program(100))
    code, out, err = run(path, "--frames", "2", "--trace-json", "--trace-pc", f"${HANDLER:04X}-${HANDLER + 8:04X}",
                         "--trace-limit", "100", capsys=capsys)
    assert code == 0, err
    steps = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    assert [s["op"] for s in steps] == ["INC $C000", "LSR $D019", "JMP $EA81"] * 2
    inc, lsr = steps[0], steps[1]
    assert (inc["frame"], inc["line"]) == (0, 100) and inc["writes"] == [[0xC000, 1]] and inc["read"] == [0xC000, 0]
    # LSR reads $D019 ($F1: raster bit latched, IRQ bit, unused bits 1) and writes $78 back (the acknowledge)
    assert lsr["read"] == [0xD019, 0xF1] and lsr["writes"] == [[0xD019, 0x78]] and lsr["flags"].endswith("C")
    assert steps[3]["frame"] == 1 and steps[3]["writes"] == [[0xC000, 2]]
    assert lsr["cycle"] - inc["cycle"] == 6   # INC abs: 6 cycles (the display is on, line 100 is no Bad Line)


def test_the_trace_limit_cuts_it_and_says_so(tmp_path, capsys):
    code, out, _ = run(prg(tmp_path, raster_irq_program(100)), "--frames", "1", "--trace", "--trace-limit", "3",
                       capsys=capsys)
    lines = out.splitlines()
    assert code == 0 and "$080D  SEI" in lines[0] and "limit of 3 steps" in lines[3]
    assert lines[1].split()[1] == "0.000.003"   # frame.line.cycle: LDA # in cycle 3 of line 0


def test_watchpoints_report_hits_with_the_beam_and_the_instruction(tmp_path, capsys):
    path = prg(tmp_path, raster_irq_program(100))
    code, out, _ = run(path, "--frames", "3", "--watch", "w:$C000=2", "--watch", f"x:${HANDLER:04X}",
                       "--watch", "r:$D019", "--json", capsys=capsys)
    hits = json.loads(out)["watch_hits"]
    assert code == 0
    assert [h["watch"] for h in hits if h["watch"] == "w:$C000=2"] == ["w:$C000=2"]   # only the second write
    executed = [h for h in hits if h["watch"].startswith("x:")]
    assert [(h["frame"], h["line"]) for h in executed] == [(0, 100), (1, 100), (2, 100)]
    assert all(h["op"] == "LSR $D019" and h["value"] == 0xF1 for h in hits if h["watch"] == "r:$D019")


@pytest.mark.parametrize("args, message", [
    (["--trace"], "needs a bound"),
    (["--watch", "w:nowhere"], "unknown label"),
    (["--watch", "q:$C000"], "KIND:ADDR"),
    (["--trace", "--trace-pc", "$0900-$0800"], "ends before it starts"),
    (["--trace-limit", "5"], "bound a --trace"),
    (["--entry", "$080D", "--trace", "--trace-json"], "one of them"),
    (["--entry", "$080D", "--watch", "w:nowhere"], "unknown label"),
])
def test_bad_input_is_one_line_exit_2(tmp_path, capsys, args, message):
    code, _, err = run(prg(tmp_path, [0x60]), *args, capsys=capsys)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err


def test_a_call_traced_as_json_lines_and_watched(capsys):
    from retro.paths import EXAMPLES_DIR

    code, out, err = run(EXAMPLES_DIR / "raster_irq_250.s", "--entry", "main", "--scene",
                       EXAMPLES_DIR / "raster_irq_250.toml", "--trace-json", "--trace-pc", "irq-$C0FF",
                       "--watch", "r:$D01E", capsys=capsys)
    steps = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    assert code == 0, err
    assert steps[0]["op"] == "PHA" and (steps[0]["line"], steps[0]["at"]) == (250, 14)
    # S is $FD in the call (the return address at $01FF/$01FE); the IRQ pushed $01FD-$01FB: PHA writes $01FA
    assert steps[0]["writes"] == [[0x01FA, steps[0]["a"]]]
    read = next(s for s in steps if s["op"] == "LDA $D01E")
    assert read["read"] == [0xD01E, 0x03] and read["a"] == 0x03   # sprites 0 and 1 met above line 250
    assert "watch r:$D01E: read $D01E = $03" in out and "line 250" in out
