"""`retro profile`: a hand-worked program with nested JSRs and a raster interrupt, every figure
computed by hand below; the picture; a handler call; a spec's cases; bad input."""

from __future__ import annotations

import json

import pytest
from PIL import Image

from retro.cli import main

# main: init with I set (KERNAL banked out, the IRQ vector at $FFFE in RAM, raster compare line 100,
# display off: no Bad Lines), then a -> b, b; CLI; JMP * until the frames run out.
# Sprite 0 (the scene) at Y 100 fetches its rows on lines 100-120: BA low in cycles 55-59 of each.
SOURCE = """
.org $c000
main:   sei
        lda #$35
        sta $01
        lda #<irq
        sta $fffe
        lda #>irq
        sta $ffff
        lda #$0b
        sta $d011
        lda #100
        sta $d012
        lda #1
        sta $d01a
        sta $d019       ; acknowledge the compare of line 0, latched before $D012 was set
        jsr a
        cli
loop:   jmp loop
a:      jsr b
        jsr b
        rts
b:      nop
        rts
irq:    pha
        jsr c
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        nop
        lsr $d019
        pla
        rti
c:      nop
        nop
        rts
"""
SCENE = """chip = "vic-ii"
[registers]
"$d011" = 0x0b
[[sprite]]
index = 0
x = 100
y = 100
rows = [""" + ", ".join(['"' + "#" * 24 + '"'] * 21) + "]\n"

# By hand (cycles from the 6502 tables; a callee's frame runs from its first instruction through
# its RTS, the caller's JSR stays the caller's; an interrupt's frame from its 7-cycle sequence
# through the RTI):
B = 2 + 6                       # NOP, RTS
A = 6 + B + 6 + B + 6           # JSR b, b, JSR b, b, RTS = 34; exclusive 34 - 16 = 18
C = 2 + 2 + 6                   # 10
# the IRQ at line 100 begins within cycles 2-10; its NOPs run from 26 cycles later for 40 cycles,
# so they hold cycles 55-59, where sprite 0's DMA stops the CPU: 5 cycles stolen, all in the NOPs
IRQ = 7 + 3 + 6 + C + 20 * 2 + 6 + 4 + 6 + 5   # = 127; exclusive 117
FRAMES = 2                      # one interrupt a frame


@pytest.fixture
def files(tmp_path):
    (tmp_path / "p.s").write_text(SOURCE)
    (tmp_path / "s.toml").write_text(SCENE)
    return tmp_path


def profile_json(*args, capsys) -> dict:
    code = main(["profile", *map(str, args), "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_the_hand_worked_profile(files, capsys):
    report = profile_json(files / "p.s", "--entry", "main", "--frames", FRAMES, "--scene", files / "s.toml",
                          capsys=capsys)
    by_name = {r["name"]: r for r in report["routines"]}
    assert set(by_name) == {"main", "a", "b", "irq", "c"}
    assert (by_name["b"]["calls"], by_name["b"]["inclusive"], by_name["b"]["exclusive"]) == (2, 2 * B, 2 * B)
    assert (by_name["a"]["calls"], by_name["a"]["inclusive"], by_name["a"]["exclusive"]) == (1, A, A - 2 * B)
    assert (by_name["c"]["calls"], by_name["c"]["inclusive"], by_name["c"]["stolen"]) == (FRAMES, FRAMES * C, 0)
    irq = by_name["irq"]
    assert irq["kind"] == "IRQ" and irq["calls"] == FRAMES
    assert (irq["min"], irq["max"], irq["inclusive"], irq["exclusive"]) == (IRQ, IRQ, FRAMES * IRQ, FRAMES * (IRQ - C))
    assert (irq["stolen"], irq["stolen_exclusive"]) == (FRAMES * 5, FRAMES * 5)
    assert irq["lines"] == [[100, 101]]          # 127 cycles from line 100, cycle 10 at the latest: ends on 101
    root = by_name["main"]
    assert root["kind"] == "entry" and root["calls"] == 1 and root["open"] == 1
    assert root["inclusive"] == report["cycles"] >= FRAMES * 19656
    assert root["exclusive"] == report["cycles"] - A - FRAMES * IRQ
    assert root["stolen"] == report["stolen"] and root["stolen_exclusive"] == report["stolen"] - FRAMES * 5
    # sprite 0's 21 fetch lines steal 5 cycles each from whatever runs, every frame
    assert report["stolen"] == FRAMES * 21 * 5


def test_text_and_picture(files, capsys, tmp_path):
    png = tmp_path / "timeline.png"
    code = main(["profile", str(files / "p.s"), "--entry", "main", "--frames", "2", "--scene",
                 str(files / "s.toml"), "--png", str(png)])
    out = capsys.readouterr().out
    assert code == 0 and "irq (IRQ)" in out and f"wrote {png}" in out
    image = Image.open(png)
    assert image.width > 63 * 6 and image.height >= 312 * 2


def test_a_handler_called_as_by_jsr(files, capsys):
    report = profile_json(files / "p.s", "--entry", "a", capsys=capsys)
    by_name = {r["name"]: r for r in report["routines"]}
    assert (by_name["a"]["inclusive"], by_name["a"]["open"], by_name["b"]["calls"]) == (A, 0, 2)
    assert report["cycles"] == A


def test_a_specs_cases(capsys):
    report = profile_json("mul8", "--cases", "100", capsys=capsys)
    assert report["source"] == "100 cases of mul8"
    (entry,) = [r for r in report["routines"] if r["kind"] == "entry"]
    assert entry["calls"] == 100 and entry["open"] == 0 and 44 <= entry["min"] <= entry["max"] <= 48   # retro check: 44-48


@pytest.mark.parametrize("args, message", [
    (["--frames", "1000000000"], "--frames"),
    (["--entry", "nowhere"], "unknown label"),
    (["--cases", "0"], "--cases"),
])
def test_bad_input_is_one_line_exit_2(files, capsys, args, message):
    code = main(["profile", str(files / "p.s"), *args] + ([] if "--entry" in args else ["--entry", "main"]))
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
