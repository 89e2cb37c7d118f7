"""`retro run CART.nes` without --entry: a cartridge on a console from its reset vector. Cartridges are
built here byte by byte (no ROM files), each program small enough to follow by hand."""

from __future__ import annotations

import json

import pytest

from retro.chips.ines import nrom_image
from retro.cli import main
from retro.commands import run

RESET = 0xC000


def cartridge(tmp_path, program: list[int], *, chr_rom: bytes | None = None, name: str = "t.nes", prg_kib: int = 16):
    prg = bytearray([0xEA] * (prg_kib * 1024))
    base = len(prg) - 0x4000               # $C000 is this offset in a 16 or 32 KiB PRG
    prg[base:base + len(program)] = bytes(program)
    prg[-4:-2] = RESET.to_bytes(2, "little")
    image = nrom_image(bytes(prg), chr_rom if chr_rom is not None else bytes(0x2000), "vertical")
    if chr_rom is None:
        image = image[:4] + bytes([image[4], 0]) + image[6:16 + len(prg)]   # no CHR ROM: CHR RAM
    path = tmp_path / name
    path.write_bytes(image)
    return path


def cli(*args, capsys):
    code = main(["run", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def text_at_6004(message: str) -> list[int]:
    code = []
    for offset, char in enumerate(message.encode() + b"\0"):
        code += [0xA9, char, 0x8D, (0x04 + offset) & 0xFF, 0x60]            # LDA #c, STA $6004+i
    return code


def blargg(status: int, message: str) -> list[int]:
    """Write the $6000 protocol: signature, text, status; then JMP * (with the NMI off)."""
    signature = [0xA9, 0xDE, 0x8D, 0x01, 0x60, 0xA9, 0xB0, 0x8D, 0x02, 0x60, 0xA9, 0x61, 0x8D, 0x03, 0x60]
    here = RESET + len(signature) + len(text_at_6004(message)) + 5
    return signature + text_at_6004(message) + [0xA9, status, 0x8D, 0x00, 0x60] + [0x4C, here & 0xFF, here >> 8]


def test_a_passing_6000_report_is_a_passed_verdict(tmp_path, capsys):
    code, out, err = cli(cartridge(tmp_path, blargg(0x00, "all good")), capsys=capsys)
    assert code == 0, err
    assert "verdict: $6000: passed" in out and "all good" in out


def test_a_failing_report_exits_1_with_its_code_and_text(tmp_path, capsys):
    code, out, _ = cli(cartridge(tmp_path, blargg(0x03, "Failed #3")), "--json", capsys=capsys)
    assert code == 1
    report = json.loads(out)
    assert report["verdict"] == {"protocol": "$6000", "code": 3, "passed": False, "text": "Failed #3"}


def test_a_jmp_to_itself_with_the_nmi_off_halts_the_run_and_the_result_byte_is_read(tmp_path, capsys):
    # LDA #1, STA $F8, JMP * (at $C004)
    code, out, _ = cli(cartridge(tmp_path, [0xA9, 0x01, 0x85, 0xF8, 0x4C, 0x04, 0xC0]), "--result", "$F8", "--json",
                       capsys=capsys)
    report = json.loads(out)
    assert (code, report["stopped"], report["halt_pc"], report["cycles"]) == (0, "halted", 0xC004, 2 + 3 + 3)
    assert report["verdict"]["passed"] is True
    code, out, _ = cli(cartridge(tmp_path, [0xA9, 0x04, 0x85, 0xF8, 0x4C, 0x04, 0xC0]), "--result", "$F8",
                       capsys=capsys)
    assert code == 1 and "failed (code 4)" in out


def test_until_an_address_and_until_a_value(tmp_path, capsys):
    # loop: INC $10 / JMP loop -- $10 counts 1, 2, ...; each turn 8 cycles
    program = [0xE6, 0x10, 0x4C, 0x00, 0xC0]
    path = cartridge(tmp_path, program)
    report = json.loads(cli(path, "--until-value", "$10=5", "--json", capsys=capsys)[1])
    assert report["stopped"] == "until-value" and report["ram"][0x10 * 2:0x10 * 2 + 2] == "05"
    assert report["cycles"] == 4 * 8 + 5
    report = json.loads(cli(path, "--until", "$C002", "--json", capsys=capsys)[1])
    assert (report["stopped"], report["cpu"]["pc"], report["cycles"]) == ("until", 0xC002, 5)


def test_the_frame_count_bounds_the_run_and_nmis_keep_it_alive(tmp_path, capsys):
    # NMI on, JMP * main loop: not a halt; the NMI handler counts frames in $20
    program = [0xA9, 0x80, 0x8D, 0x00, 0x20, 0x4C, 0x05, 0xC0]
    handler = RESET + 0x100
    prg_program = program + [0xEA] * (0x100 - len(program)) + [0xE6, 0x20, 0x40]
    path = cartridge(tmp_path, prg_program)
    data = bytearray(path.read_bytes())
    data[16 + 0x3FFA:16 + 0x3FFC] = handler.to_bytes(2, "little")
    path.write_bytes(bytes(data))
    report = json.loads(cli(path, "--frames", 3, "--json", "--peek", "$20", capsys=capsys)[1])
    assert report["stopped"] == "frames" and report["peek"] == {"$20": [3]}
    assert report["cycles"] >= 3 * 29780


def test_the_console_around_the_cpu(tmp_path, capsys):
    # STA $0812 (RAM mirror of $0012), LDA $4015 -> $30, LDA $4016 -> $31, STA $8000 (ROM: ignored),
    # then $2006/$2007 write $AB to CHR $0000 and read it back through the buffer into $32; JMP *
    program = [0xA9, 0x77, 0x8D, 0x12, 0x08, 0xAD, 0x15, 0x40, 0x85, 0x30, 0xAD, 0x16, 0x40, 0x85, 0x31,
               0x8D, 0x00, 0x80,
               0xA9, 0x00, 0x8D, 0x06, 0x20, 0x8D, 0x06, 0x20, 0xA9, 0xAB, 0x8D, 0x07, 0x20,
               0xA9, 0x00, 0x8D, 0x06, 0x20, 0x8D, 0x06, 0x20, 0xAD, 0x07, 0x20, 0xAD, 0x07, 0x20, 0x85, 0x32,
               0x4C, 0x2F, 0xC0]
    for chr_rom, expected in ((None, 0xAB), (bytes([0x5A]) * 0x2000, 0x5A)):   # CHR RAM takes it, CHR ROM not
        path = cartridge(tmp_path, program, chr_rom=chr_rom)
        report = json.loads(cli(path, "--json", "--peek", "$0012", "--peek", "$30:3", "--peek", "$8000", capsys=capsys)[1])
        assert report["stopped"] == "halted", report["stopped"]
        assert report["peek"] == {"$0012": [0x77], "$30": [0x00, 0x40, expected], "$8000": [0xA9]}


@pytest.mark.parametrize("args, message", [
    (["--frames", "1000000000"], "--frames"),
    (["--frames", "0"], "--frames"),
    (["--until", "nowhere"], "unknown label"),
    (["--until-value", "$10=1,2"], "one byte"),
    (["--entry", "$C000", "--frames", "3"], "only for a program run"),
    (["--scene", "x.toml"], "--scene"),
])
def test_bad_options_are_one_line_exit_2(tmp_path, capsys, args, message):
    code, out, err = cli(cartridge(tmp_path, [0x4C, 0x00, 0xC0]), *args, capsys=capsys)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err


def test_without_entry_a_non_cartridge_is_refused(tmp_path, capsys):
    path = tmp_path / "p.prg"
    path.write_bytes(bytes([0x00, 0xC0, 0x60]))
    code, _, err = cli(path, capsys=capsys)
    assert code == 2 and "loads at $C000, not at BASIC's $0801" in err and "--entry" in err


def test_other_mappers_are_refused_naming_the_file(tmp_path, capsys):
    path = cartridge(tmp_path, [0x4C, 0x00, 0xC0])
    data = bytearray(path.read_bytes())
    data[6] |= 0x10                                          # mapper 1
    path.write_bytes(bytes(data))
    code, _, err = cli(path, capsys=capsys)
    assert code == 2 and "mapper 1" in err and str(path) in err


def test_ctrl_c_ends_the_run_with_the_report_so_far(tmp_path, monkeypatch):
    from retro.cpu.machine import Machine
    calls = []
    original = Machine.run_on

    def interrupted(self, cycles, **kwargs):
        if calls:
            raise KeyboardInterrupt
        calls.append(cycles)
        return original(self, cycles, **kwargs)

    monkeypatch.setattr(Machine, "run_on", interrupted)
    report = run.run_console(cartridge(tmp_path, [0xE6, 0x10, 0x4C, 0x00, 0xC0]), frames=10)
    assert report.stopped == "interrupted"
    assert 29780 <= report.cycles < 2 * 29781
    assert "interrupted (Ctrl-C)" in "\n".join(run.lines(report))


def test_a_traced_cartridge_shows_scanline_and_dot_and_a_watch_sees_the_write(tmp_path, capsys):
    # INC $10 / JMP $C000: 5 + 3 cycles a turn, 3 dots a CPU cycle
    path = cartridge(tmp_path, [0xE6, 0x10, 0x4C, 0x00, 0xC0])
    code, out, _ = cli(path, "--frames", "1", "--trace-json", "--trace-limit", "3", "--watch", "w:$10=3",
                       "--json", capsys=capsys)
    lines = out.splitlines()
    steps = [json.loads(line) for line in lines[:3]]
    assert code == 0 and [(s["line"], s["at"]) for s in steps] == [(0, 0), (0, 15), (0, 24)]
    assert steps[0]["writes"] == [[0x10, 1]] and steps[0]["op"] == "INC $10"
    report = json.loads(lines[-1])
    hits = report["watch_hits"]   # $10 holds 3 again every 256 turns: 3722 turns in a frame
    assert len(hits) == 15 and all(h["value"] == 3 and h["op"] == "INC $10" for h in hits)
    assert (hits[0]["cycle"], hits[0]["line"], hits[0]["at"]) == (16, 0, 48)
    assert hits[1]["cycle"] - hits[0]["cycle"] == 256 * 8


def test_an_nmi_handlers_vblank_budget_counts_oam_dma(tmp_path, capsys):
    # the handler: LDA #$02 / STA $4014 (OAM DMA from page 2) / RTS, called at the start of vblank
    source = tmp_path / "nmi.s"
    source.write_text(".org $c000\nnmi:    lda #$02\n        sta $4014\n        rts\n")
    scene = tmp_path / "s.toml"
    scene.write_text('chip = "nes"\n[[oam]]\ny = 100\ntile = 0\nx = 100\n')
    code = main(["run", str(source), "--entry", "nmi", "--scene", str(scene), "--in-nmi", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    v = json.loads(out)["vblank"]
    # entered 7 cycles (21 dots) after the vblank flag (line 241, dot 1): line 241 dot 22, CPU cycle 27,401
    # of the frame; the pre-render line (261) starts at dot 89,001: 2,266 cycles of vblank for the handler
    assert (v["start_line"], v["start_dot"]) == (241, 22)
    assert v["oam_dma_cycles"] in (513, 514) and v["cycles"] == 2 + 4 + 6 + v["oam_dma_cycles"]
    assert v["vblank_cycles_left"] == 2266 - v["cycles"]
    code = main(["run", str(source), "--entry", "nmi", "--in-nmi"])
    assert code == 2 and "--in-nmi: needs a NES scene" in capsys.readouterr().err
