"""`load_program`: PRG, raw binary, iNES (NROM) and Ophis source, told apart by content; foreign
source and bad files refused in one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from retro.chips.ines import nrom_image
from retro.errors import InputError
from retro.loaders import load_program, refuse_foreign_source

FOREIGN = Path(__file__).resolve().parent.parent / "data" / "foreign"
CHR = bytes(0x2000)


def test_prg_with_any_symbol_format():
    program = load_program(FOREIGN / "dasm_boxhit.prg", symbols=FOREIGN / "dasm_boxhit.sym")
    assert (program.origin, len(program.code), program.cpu) == (0xC000, 0x53, None)
    assert program.code[:3] == bytes([0xAD, 0x4B, 0xC0])  # LDA boxb_x, from dasm_boxhit.lst line 12
    assert program.symbols["boxhit"] == 0xC000 and program.ambiguous == {"loop": ("1::loop", "2::loop")}
    with pytest.raises(InputError, match=r"label 'loop' is defined more than once \(1::loop, 2::loop\)"):
        program.address_of("loop")


def test_raw_binary_needs_its_load_address():
    program = load_program(FOREIGN / "xa_boxhit.bin", symbols=FOREIGN / "xa_boxhit.labels", load="$c000")
    assert program.origin == 0xC000
    assert program.code == (FOREIGN / "acme_boxhit.prg").read_bytes()[2:]  # the same routine, without a header
    assert program.symbols["loop@$C043"] == 0xC043
    with pytest.raises(InputError) as error:
        load_program(FOREIGN / "xa_boxhit.bin")
    assert str(error.value).startswith(f"{FOREIGN / 'xa_boxhit.bin'}: a binary file without a load address")


def test_raw_binary_past_the_address_space(tmp_path):
    path = tmp_path / "big.bin"
    path.write_bytes(bytes(0x20))
    with pytest.raises(InputError, match=r"big.bin: 32 bytes at \$FFF0 run past \$FFFF"):
        load_program(path, load="$fff0")
    assert load_program(path, load="$ffe0").end == 0x10000
    with pytest.raises(InputError, match="--load"):
        load_program(path, load="$10000")


def test_nrom_128_is_mirrored_and_names_its_vectors():
    program = load_program(FOREIGN / "nes_boxhit.nes")
    assert (program.cpu, program.origin, len(program.code)) == ("2a03", 0x8000, 0x8000)
    assert program.code[:0x4000] == program.code[0x4000:]
    # the vectors as nes_boxhit.s sets them: .word on_nmi, start, on_irq ($C03E, $C036, $C03E in nes_boxhit.lbl)
    assert {name: program.symbols[name] for name in ("nmi", "reset", "irq")} == \
        {"nmi": 0xC03E, "reset": 0xC036, "irq": 0xC03E}
    assert program.symbols["vector:reset"] == 0xC036
    with_labels = load_program(FOREIGN / "nes_boxhit.nes", symbols=FOREIGN / "nes_boxhit.dbg")
    assert with_labels.symbols["start"] == 0xC036 and with_labels.symbols["boxb_x"] == 0x0300


def test_a_user_label_named_like_a_vector_wins(tmp_path):
    labels = tmp_path / "mine.lbl"
    labels.write_text("al C:c000 .reset\n")
    program = load_program(FOREIGN / "nes_boxhit.nes", symbols=labels)
    assert program.symbols["reset"] == 0xC000 and program.symbols["vector:reset"] == 0xC036


def test_nrom_256_fills_8000_to_ffff(tmp_path):
    prg = bytearray(b"\xff" * 0x8000)
    prg[0:3] = bytes([0xA9, 0x42, 0x60])  # $8000: LDA #$42 / RTS
    prg[0x7FFC:0x7FFE] = bytes([0x00, 0x80])  # reset vector -> $8000
    path = tmp_path / "big.nes"
    path.write_bytes(nrom_image(bytes(prg), CHR, "vertical"))
    program = load_program(path)
    assert (program.origin, program.code) == (0x8000, bytes(prg)) and program.symbols["reset"] == 0x8000


@pytest.mark.parametrize("mutate, needle", [
    (lambda image: image[:6] + bytes([0x10]) + image[7:], "iNES mapper 1 is not supported; only mapper 0 (NROM)"),
    (lambda image: image[:0x1000], "truncated: the header promises 16384 bytes of PRG ROM"),
    (lambda image: image[:4] + bytes([3]) + image[5:], "NROM needs 16 or 32 KiB of PRG ROM"),
    (lambda image: b"NES\x1b" + image[4:], "a binary file without a load address"),
])
def test_bad_ines_images_give_one_line(tmp_path, mutate, needle):
    path = tmp_path / "bad.nes"
    path.write_bytes(mutate((FOREIGN / "nes_boxhit.nes").read_bytes()))
    with pytest.raises(InputError) as error:
        load_program(path)
    assert str(error.value).startswith(f"{path}: ") and needle in str(error.value)


def test_ophis_source_is_assembled(tmp_path):
    path = tmp_path / "inc.s"
    path.write_text("        .org $1000\ninc_x:  inx\n        rts\n")
    program = load_program(path)
    assert (program.origin, program.code, program.symbols) == (0x1000, bytes([0xE8, 0x60]), {"inc_x": 0x1000})
    with pytest.raises(InputError, match=r"a symbol file \(--labels\) goes with a \.prg"):
        load_program(path, symbols=FOREIGN / "acme_boxhit.lbl")


@pytest.mark.parametrize("source, assembler", [
    ("acme_boxhit.asm", "ACME"), ("64tass_boxhit.asm", "64tass"), ("ca65_boxhit.s", "ca65"),
    ("dasm_boxhit.asm", "DASM"), ("xa_boxhit.asm", "xa"), ("kick_boxhit.asm", "Kick Assembler"),
])
def test_another_assemblers_source_is_refused_naming_it(source, assembler):
    with pytest.raises(InputError) as error:
        load_program(FOREIGN / source)
    assert str(error.value) == (f"{FOREIGN / source}: not Ophis source (looks like {assembler}); assemble it with "
                                f"your assembler and pass the .prg and --labels")


@pytest.mark.parametrize("text, assembler", [
    ("* = $c000\nstart lda #1\n", "ACME, 64tass or xa"),
    ("        !to \"x.prg\", cbm\n", "ACME"),
    ("*=$0801 \"Basic\"\n", "Kick Assembler"),
    ("  .pc = $c000\n", "Kick Assembler"),
    ("start:\n  .segment \"CODE\"\n", "ca65"),
    ("  processor 6502\n", "DASM"),
    ("loop    dc.b 1,2\n", "DASM"),
    ("table .byt 1, 2\n", "xa"),
])
def test_foreign_syntax_clues(tmp_path, text, assembler):
    with pytest.raises(InputError, match=f"looks like {assembler}"):
        refuse_foreign_source("x.s", text.encode())


def test_ophis_sources_are_not_mistaken_for_foreign_ones():
    text = ("; lda org, jmp hex: operands named like DASM directives\n"
            "        .org $c000\n.alias org $10\n.scope\n_loop:  lda org\n        jmp hex\n.scend\n"
            "hex:    .byte 1\n        .word hex\n        .text\n        .data\n        .space buf 4\n")
    assert refuse_foreign_source("ok.s", text.encode()) == text


def test_binary_given_as_source_and_empty_files(tmp_path):
    with pytest.raises(InputError, match=r"^x.s: not Ophis source \(a binary file\)$"):
        refuse_foreign_source("x.s", bytes([0x00, 0xC0, 0xA9]))
    empty = tmp_path / "empty.s"
    empty.write_text("")
    with pytest.raises(InputError, match="empty.s: empty file"):
        load_program(empty)
    short = tmp_path / "short.prg"
    short.write_bytes(b"\x01")
    with pytest.raises(InputError, match="2-byte load address"):
        load_program(short)
