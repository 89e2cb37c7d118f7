"""`retro run PROG.prg`: a C64 program from its BASIC SYS line (or --entry) for N frames or until a
condition, on the 6510 with the VIC-II's timeline. Programs are built here byte by byte, each small
enough to follow by hand."""

from __future__ import annotations

import json

import pytest

from retro.cli import main
from retro.chips.vic.constants import PAL
from retro.loaders.basic_stub import sys_line
from retro.program import Program

CODE = 0x080D  # right after the stub `10 SYS 2061`


def basic_stub(text: bytes = b"\x9e2061", number: int = 10) -> bytes:
    """One tokenised BASIC line at $0801 and the end of the program."""
    line = bytes([number & 0xFF, number >> 8]) + text + b"\0"
    link = 0x0801 + 2 + len(line)
    return bytes([link & 0xFF, link >> 8]) + line + b"\0\0"


def prg(tmp_path, code: list[int], *, stub: bytes | None = None, origin: int = 0x0801, name: str = "p.prg"):
    body = (basic_stub() if stub is None else stub) + bytes(code) if origin == 0x0801 else bytes(code)
    path = tmp_path / name
    path.write_bytes(origin.to_bytes(2, "little") + body)
    return path


def cli(*args, capsys):
    code = main(["run", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def run_json(*args, capsys) -> dict:
    code, out, err = cli(*args, "--json", capsys=capsys)
    assert code == 0, err
    return json.loads(out)


def test_the_sys_line_is_found_and_an_rts_ends_the_run(tmp_path, capsys):
    # LDA #1 / STA $C000 / RTS: 2 + 4 + 6 cycles from the SYS address; A, X, Y, P as SYS loads them (0)
    report = run_json(prg(tmp_path, [0xA9, 0x01, 0x8D, 0x00, 0xC0, 0x60]), "--peek", "$C000", capsys=capsys)
    assert (report["entry"], report["sys_line"], report["stopped"]) == (2061, 10, "returned")
    assert report["cycles"] == 12 and report["instructions"] == 3
    assert report["peek"] == {"$C000": [1]}
    assert report["ram"][0xC000 * 2:0xC000 * 2 + 2] == "01"
    assert report["cpu"]["a"] == 1 and report["cpu"]["p"] & 0x04 == 0   # I clear, as after SYS


@pytest.mark.parametrize("text, address", [(b" \x9e 2 0 6 1", 2061), (b"\x9e(2061)", 2061),
                                           (b"\x8f\x9e49152", None), (b'\x99"\x9e":\x9e4096', 4096)])
def test_the_sys_number_is_read_as_basic_reads_it(text, address):
    program = Program(code=basic_stub(text), origin=0x0801, source="p.prg")
    if address is None:   # a SYS after REM is a comment
        with pytest.raises(Exception, match="no BASIC line with a SYS"):
            sys_line(program)
    else:
        found = sys_line(program)
        assert found.address == address
        assert bool(found.notes) == (text[0] == 0x99)   # PRINT "..." runs before the SYS on the machine


@pytest.mark.parametrize("code, origin, args, message", [
    ([0x60], 0xC000, [], "loads at $C000, not at BASIC's $0801"),
    ([], 0x0801, [], "no BASIC line with a SYS"),
    ([0x60], 0x0801, ["--frames", "1000000000"], "--frames"),
    ([0x60], 0x0801, ["--result", "$F8"], "--result"),
    ([0x60], 0x0801, ["--until", "nowhere"], "unknown label"),
    ([0x60], 0x0801, ["--trace"], "--trace"),
])
def test_bad_input_is_one_line_exit_2(tmp_path, capsys, code, origin, args, message):
    stub = b"\0\0" if not code else None
    path = prg(tmp_path, code, origin=origin, stub=stub)
    status, _, err = cli(path, *args, capsys=capsys)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1, err


def test_a_sys_with_an_expression_is_refused(tmp_path, capsys):
    path = prg(tmp_path, [0x60], stub=basic_stub(b"\x9e4096\xaa12"))   # SYS 4096+12
    status, _, err = cli(path, capsys=capsys)
    assert status == 2 and "plain number" in err


def test_a_given_entry_runs_a_program_loaded_anywhere(tmp_path, capsys):
    # at $C000: INC $02 / JMP $C000 -- 5 + 3 cycles a turn; stop when $02 holds 4
    path = prg(tmp_path, [0xE6, 0x02, 0x4C, 0x00, 0xC0], origin=0xC000)
    report = run_json(path, "--entry", "$C000", "--until-value", "$02=4", capsys=capsys)
    assert report["stopped"] == "until-value" and report["sys_line"] is None
    assert report["cycles"] == 3 * 8 + 5


def test_jmp_to_itself_with_interrupts_off_halts(tmp_path, capsys):
    report = run_json(prg(tmp_path, [0x78, 0x4C, 0x0E, 0x08]), capsys=capsys)   # SEI / JMP *
    assert (report["stopped"], report["halt_pc"], report["cycles"]) == ("halted", 0x080E, 2 + 3)


def raster_irq_program(line: int) -> list[int]:
    """SEI; $0314 = handler; $D011 = $1B (compare bit 8 clear: the KERNAL leaves it set); $D012 = line;
    $D01A = 1; CLI; JMP * -- the handler: INC $C000, LSR $D019 (acknowledge), JMP $EA81 (the
    KERNAL's exit: PLA/TAY/PLA/TAX/PLA/RTI)."""
    handler = CODE + 30
    main = [0x78,                                   # SEI
            0xA9, handler & 0xFF, 0x8D, 0x14, 0x03,  # LDA #<handler / STA $0314
            0xA9, handler >> 8, 0x8D, 0x15, 0x03,   # LDA #>handler / STA $0315
            0xA9, 0x1B, 0x8D, 0x11, 0xD0,           # LDA #$1B / STA $D011
            0xA9, line, 0x8D, 0x12, 0xD0,           # LDA #line / STA $D012
            0xA9, 0x01, 0x8D, 0x1A, 0xD0,           # LDA #1 / STA $D01A
            0x58,                                   # CLI
            0x4C, (CODE + 27) & 0xFF, (CODE + 27) >> 8]  # JMP *
    assert len(main) == 30
    return main + [0xEE, 0x00, 0xC0, 0x4E, 0x19, 0xD0, 0x4C, 0x81, 0xEA]


def test_a_raster_interrupt_through_0314_runs_once_a_frame(tmp_path, capsys):
    report = run_json(prg(tmp_path, raster_irq_program(100)), "--frames", "3", "--peek", "$C000", capsys=capsys)
    assert report["stopped"] == "frames" and report["peek"] == {"$C000": [3]}
    assert report["cycles"] >= 3 * PAL.frame_cycles and report["vic"]["d019"] & 0x01 == 0


def test_bad_lines_steal_cycles_only_with_the_display_on(tmp_path, capsys):
    # the KERNAL's $D011 ($9B) has the display on: Bad Lines steal 40-43 cycles each of 25 text rows
    path = prg(tmp_path, [0x4C, 0x0D, 0x08])   # JMP * with I clear and no VIC-II source: runs the frame
    report = run_json(path, "--frames", "1", capsys=capsys)
    assert report["stopped"] == "halted"        # no interrupt can come: ends at once
    stolen_on = []
    for d011 in ("$1B", "$0B"):                 # display on / off (DEN)
        scene = tmp_path / f"s{d011[1:]}.toml"
        scene.write_text(f'chip = "vic-ii"\n[registers]\n"$d011" = {int(d011[1:], 16)}\n')
        path = prg(tmp_path, [0xE6, 0x02, 0x4C, 0x0D, 0x08])   # INC $02 / JMP loop
        code, out, err = cli(path, "--frames", "1", "--scene", scene, capsys=capsys)
        assert code == 0, err
        stolen_on.append(int(out.split(" stolen")[0].rsplit(", ", 1)[1]))
    assert 25 * 40 <= stolen_on[0] <= 25 * 43 and stolen_on[1] == 0


def test_a_kernal_call_is_an_error_naming_the_address_and_the_caller(tmp_path, capsys):
    status, _, err = cli(prg(tmp_path, [0xA9, 0x41, 0x20, 0xD2, 0xFF, 0x60]), capsys=capsys)
    assert status == 1 and "$FFD2 (CHROUT)" in err and "from $080F JSR $FFD2" in err
    assert len(err.strip().splitlines()) == 1


def test_with_the_kernal_banked_out_its_addresses_are_ram(tmp_path, capsys):
    # LDA #$60 / STA $E000 (an RTS in the RAM under the KERNAL) / LDA #$35 / STA $01 / JSR $E000 / RTS
    code = [0xA9, 0x60, 0x8D, 0x00, 0xE0, 0xA9, 0x35, 0x85, 0x01, 0x20, 0x00, 0xE0, 0x60]
    assert run_json(prg(tmp_path, code), capsys=capsys)["stopped"] == "returned"
    # with the KERNAL in, the same JSR is refused
    code[6] = 0x37
    status, _, err = cli(prg(tmp_path, code), capsys=capsys)
    assert status == 1 and "KERNAL ROM at $E000" in err
