"""Every kind of line each assembler writes in its symbol file: read when it gives an address,
skipped and counted when it does not, a one-line error when no assembler writes it.

The files are the assemblers' own output (tests/data/symbols/README.md has the commands). The
expected addresses are read off the assemblers' listings in that folder (e.g. dasm_kinds.lst line
81 `c055 ca 1$ dex`, 64tass_kinds.lst `.c005 ca dex _loop`), and the expected skip counts off the
symbol files themselves (the README's table), never from the parser.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from retro.cli import main
from retro.errors import InputError
from retro.loaders import symbol_tables
from retro.loaders.symbols import (
    MONITOR_COMMAND,
    NOT_INTEGER,
    OUT_OF_RANGE,
    STRING,
    STRING_MACRO,
    UNRESOLVED,
    parse_symbol_file,
    read_symbol_file,
)

KINDS = Path(__file__).resolve().parent.parent / "data" / "symbols"

BOXHIT = {"boxhit": 0xC000, "miss": 0xC034, "fill": 0xC036, "sum": 0xC03F, "boxb_x": 0xC04B, "boxb_y": 0xC04C,
          "boxb_w": 0xC04D, "boxb_h": 0xC04E, "buf": 0xC04F, "boxa_x": 0xFB, "boxa_y": 0xFC, "boxa_w": 0xFD,
          "boxa_h": 0xFE}
DASM = {**BOXHIT, "1.loop": 0xC038, "2.loop": 0xC043, "wait": 0xC053, "10$1$": 0xC055, "3.done": 0xC058,
        "3::done": 0xC058, "COUNT": 4}  # COUNT: the last SET (3, then COUNT+1)
ACME = {"start": 0xC000, "later": 0xC011, "unused": 0xC014, "boxa_x": 0xFB, "ptr": 0xFB, "SCREEN": 0x400,
        "FORWARD": 0x400, "LETTER": 0x41, "COUNT": 3}
TASS = {"start": 0xC000, "later": 0xC00C, "moved": 0x400, "boxa_x": 0xFB, "DECIMAL": 0xC001, "COUNT": 5}
TASS_SCOPED = {"start._loop": 0xC005, "start::_loop": 0xC005, "later.loop": 0xC00C, "later::loop": 0xC00C}
TASS_VICE = {"start": 0xC000, "later": 0xC00C, "moved": 0x400, "start:_loop": 0xC005, "later:loop": 0xC00C}
CA65 = {"start": 0xC000, "later": 0xC011, "later::loop": 0xC011, "outer::inner": 0xC015,
        "outer::inner::deep": 0xC015, "start::@cheap": 0xC004, "counter": 0x02, "FORWARD": 0x400, "boxa_x": 0xFB,
        "Point::xc": 0, "Point::yc": 1, "Color::red": 0, "Color::green": 5}
CA65_LN = {"start": 0xC000, "later": 0xC011, "loop": 0xC011, "deep": 0xC015, "@cheap": 0xC004, "counter": 0x02,
           "FORWARD": 0x400, "boxa_x": 0xFB, "__LOADADDR__": 0x0001}
XA = {"start": 0xC000, "later": 0xC008, "shared": 0xC008, "loop@$C005": 0xC005, "loop@$C009": 0xC009,
      "boxa_x": 0xFB, "FORWARD": 0x400}

# file -> (format, {name: address} that must be read, {kind: count} skipped, names never read)
CASES = {
    "dasm_kinds.sym": ("DASM -s", DASM, {STRING_MACRO: 2, STRING: 1, UNRESOLVED: 2, OUT_OF_RANGE: 2},
                       {"PLAYER_Y", "HUD_TEXT", "TITLE", "PAL", "NO_ILLEGAL_OPCODES", "DELTA", "WIDE"}),
    "dasm_kinds_by_address.sym": ("DASM -s", DASM, {STRING_MACRO: 2, STRING: 1, UNRESOLVED: 2, OUT_OF_RANGE: 2},
                                  {"TITLE", "DELTA", "WIDE"}),
    "acme_kinds.sym": ("ACME --symbollist / 64tass --labels", ACME, {OUT_OF_RANGE: 2, NOT_INTEGER: 1},
                       {"DELTA", "WIDE", "RATIO", "ptr+2"}),
    "acme_kinds_typed.sym": ("ACME --symbollist / 64tass --labels", ACME, {OUT_OF_RANGE: 2, NOT_INTEGER: 1},
                             {"DELTA", "WIDE", "RATIO", "!addr"}),
    "acme_kinds.lbl": ("VICE labels", ACME, {OUT_OF_RANGE: 2}, {"DELTA", "WIDE", "RATIO"}),
    "64tass_kinds.labels": ("ACME --symbollist / 64tass --labels", TASS,
                            {STRING: 2, UNRESOLVED: 1, OUT_OF_RANGE: 4, NOT_INTEGER: 8},
                            {"DELTA", "MASK", "WIDE", "HUGE", "TITLE", "LETTER", "GAP", "REG", "RATIO", "TINY"}),
    "64tass_kinds.dump": ("64tass --dump-labels", {**TASS, **TASS_SCOPED},
                          {STRING: 2, UNRESOLVED: 1, OUT_OF_RANGE: 4, NOT_INTEGER: 8}, {"DELTA", "MASK", "HUGE"}),
    "64tass_kinds.vice": ("VICE labels", TASS_VICE, {}, {"boxa_x", "DECIMAL"}),  # code labels only
    "64tass_kinds.vicenum": ("VICE labels", {**TASS_VICE, "boxa_x": 0xFB, "DECIMAL": 0xC001}, {OUT_OF_RANGE: 2},
                             {"MASK", "WIDE"}),
    "ca65_kinds.dbg": ("ca65/ld65 --dbgfile", CA65, {OUT_OF_RANGE: 2}, {"DELTA", "WIDE", "TITLE"}),
    "ca65_kinds.lbl": ("VICE labels", CA65_LN, {OUT_OF_RANGE: 2}, {"DELTA", "WIDE"}),
    "xa_kinds.labels": ("xa -l", XA, {OUT_OF_RANGE: 2}, {"DELTA", "WIDE"}),
    "xa_kinds_xref.labels": ("xa -l", XA, {OUT_OF_RANGE: 2}, {"DELTA", "WIDE"}),
    "xa_reloc.labels": ("xa -l", {"start": 0x1000, "counter": 0x400}, {UNRESOLVED: 1}, {"kernal_chrout"}),
}


@pytest.mark.parametrize("file", sorted(CASES))
def test_every_line_kind_is_read_or_counted(file):
    expected_format, addresses, skipped, absent = CASES[file]
    symbol_file = read_symbol_file(KINDS / file)
    assert symbol_file.format == expected_format
    assert dict(symbol_file.skipped) == skipped
    table, _ = symbol_tables(symbol_file.symbols)
    assert {name: table.get(name) for name in addresses} == addresses
    assert not absent & set(table)
    assert all(0 <= address <= 0xFFFF for address in table.values())


def test_a_negative_is_never_wrapped_into_the_address_space():
    # DELTA = -16 in ca65_kinds.s: ld65 writes 0xFFFFFFF0; nothing may land on $FFF0 (or $FF80 for -128)
    for file in CASES:
        table, ambiguous = symbol_tables(read_symbol_file(KINDS / file).symbols)
        assert not {0xFFF0, 0xFF80, 0xFFFF} & set(table.values()), file


def test_the_note_says_each_count_once():
    note = read_symbol_file(KINDS / "dasm_kinds.sym").note
    assert note == (f"{KINDS / 'dasm_kinds.sym'}: 19 symbols read; skipped 2 string macros, 1 string constant, "
                    f"2 unresolved names, 2 constants outside $0000-$FFFF (lines without an address)")
    assert read_symbol_file(KINDS / "64tass_kinds.vice").note == ""  # nothing skipped, nothing said


# ---- line kinds no fixture produces (written from each assembler's source, cited) --------------

def test_dasm_unsorted_dump_and_long_names():
    # main.c ShowSymbols: without memory to sort, `%-24s %s` lines under " (unsorted - ...)"; a name
    # longer than 24 characters is followed by one space
    text = ("--- Symbol List (unsorted - not enough memory to sort!)\n"
            "a_name_longer_than_twenty_four c000 \n"
            "SETVAR                   0003              ( S)\n"
            "--- End of Symbol List.\n")
    symbol_file = parse_symbol_file(text, "d.sym")
    assert [(s.name, s.address) for s in symbol_file.symbols] == [("a_name_longer_than_twenty_four", 0xC000),
                                                                  ("SETVAR", 3)]


def test_dasm_32_bit_long_negative_is_out_of_range():
    # where a C long is 32 bits (Windows builds), -128 is ffffff80
    text = "--- Symbol List (sorted by symbol)\nNEG      ffffff80\nok  c000\n--- End of Symbol List.\n"
    assert dict(parse_symbol_file(text, "d").skipped) == {OUT_OF_RANGE: 1}


def test_acme_undefined_symbol_is_unresolved():
    # ACME symbol.c dump_one_symbol: an undefined number is written as ` ?` after `= `
    symbol_file = parse_symbol_file("\tok\t= $c000\n\tlater\t=  ?\t; ?\n", "a.sym")
    assert [s.name for s in symbol_file.symbols] == ["ok"] and dict(symbol_file.skipped) == {UNRESOLVED: 1}


def test_acme_forced_24_bit_width_suffix():
    symbol_file = parse_symbol_file("\tfar+3\t= $c000\t; unused\n", "a.sym")
    assert [(s.name, s.address) for s in symbol_file.symbols] == [("far", 0xC000)]


def test_kick_values_of_every_kind():
    text = ('.label start=$0810\n.const COLS=40\n.const NEG=-1\n.const PI=3.14159\n.const NAME="JOE"\n'
            '.const ON=true\n.namespace game {\n  .label loop=$0820\n}\n')
    symbol_file = parse_symbol_file(text, "k.sym")
    table, _ = symbol_tables(symbol_file.symbols)
    assert table == {"start": 0x810, "COLS": 40, "game::loop": 0x820, "game.loop": 0x820, "loop": 0x820}
    assert dict(symbol_file.skipped) == {STRING: 1, OUT_OF_RANGE: 1, NOT_INTEGER: 2}


def test_kick_vice_file_monitor_commands_are_counted():
    text = "al C:0810 .start\nbreak 0815\nwatch store 0400\nal C:0820 .game.loop\n"
    symbol_file = parse_symbol_file(text, "k.vs")
    assert len(symbol_file.symbols) == 2 and dict(symbol_file.skipped) == {MONITOR_COMMAND: 2}


# ---- strict numbers --------------------------------------------------------------------------

HUGE_DECIMAL = "9" * 5000
HUGE_HEX = "f" * 5000


@pytest.mark.parametrize("text", [
    f"ok = $c000\nhuge = {HUGE_DECIMAL}\n",                                 # 64tass: integers of any size
    f"ok = $c000\nhuge = ${HUGE_HEX}\n",
    f"ok = $c000\nhuge = -{HUGE_DECIMAL}\n",
    f"\tok\t= $c000\n\thuge\t= ${HUGE_HEX}\t; unused\n",                      # ACME's form of the same line
    f"a.s:1:1: ok = $c000\na.s:2:1: huge = {HUGE_DECIMAL}\n",
    f".label ok=$c000\n.const huge={HUGE_DECIMAL}\n",
    f".label ok=$c000\n.const huge=${HUGE_HEX}\n",
], ids=["64tass-decimal", "64tass-hex", "64tass-negative", "acme", "64tass-dump", "kick-decimal", "kick-hex"])
def test_a_5000_digit_integer_where_the_assembler_allows_any_size_is_a_skipped_constant(text):
    symbol_file = parse_symbol_file(text, "f")
    assert [s.name for s in symbol_file.symbols] == ["ok"] and dict(symbol_file.skipped) == {OUT_OF_RANGE: 1}


@pytest.mark.parametrize("text, start", [
    (f"al C:c000 .ok\nal C:{HUGE_HEX} .huge\n", "f:2: 5000-digit number in the address of 'huge'"),
    (f"--- Symbol List (sorted by symbol)\nhuge  {HUGE_HEX}\n--- End of Symbol List.\n",
     "f:2: 5000-digit number in the value of 'huge'"),
    (f"huge, 0x{HUGE_HEX}, 0, 0x0000\n", "f:1: 5000-digit number in the value of 'huge'"),
    ('version\tmajor=2,minor=0\nscope\tid=0,name=""\n'
     f'sym\tid=0,name="huge",scope=0,val=0x{HUGE_HEX},type=equ\n', "f:3: 5000-digit number in field 'val'"),
    ('version\tmajor=2,minor=0\nscope\tid=0,name=""\nsym\tid=0,name="neg",scope=0,val=-0x10,type=equ\n',
     "f:3: field 'val' missing or not a number"),
    ('version\tmajor=2,minor=0\nscope\tid=0,name=""\n'
     f'sym\tid={HUGE_DECIMAL},name="x",scope=0,val=0x10,type=equ\n', "f:3: 5000-digit number in field 'id'"),
], ids=["vice", "dasm", "xa", "dbg-val", "dbg-negative", "dbg-id"])
def test_a_number_wider_than_the_assembler_writes_is_one_line(text, start):
    with pytest.raises(InputError) as error:
        parse_symbol_file(text, "f")
    message = str(error.value)
    assert message.startswith(start) and "\n" not in message and len(message) < 200


# ---- lines no assembler writes ---------------------------------------------------------------

@pytest.mark.parametrize("text, start", [
    ("--- Symbol List (sorted by symbol)\nok  c000\nbad  c000  (X )\n--- End of Symbol List.\n", "f:3: expected"),
    ("--- Symbol List (sorted by symbol)\nok  c000\nbad  zz\n--- End of Symbol List.\n", "f:3: expected"),
    ("--- Symbol List (sorted by symbol)\nbad  0000  str eqm ( S)\n--- End of Symbol List.\n", "f:2: expected"),
    ("--- Symbol List (sorted by symbol)\nok  c000\n", "f: truncated: no '--- End of Symbol List.'"),
    ("--- Symbol List (sorted by symbol)\n--- End of Symbol List.\nlate  c000\n", "f:3: expected"),
    ("\tok\t= $c000\t; hello\n", "f:1: expected 'name = $ADDR'"),
    ("ok = $c000\nbad = what is this\n", "f:2: expected 'name = $ADDR'"),
    ("ok = $c000\nbad = $c0zz\n", "f:2: expected 'name = $ADDR'"),
    ("ok = $c000\nbad = \"unclosed\n", "f:2: expected 'name = $ADDR'"),
    ("ok, 0xc000, 0, 0x0000\nfoo, 0xzz, 1, 2\n", "f:2: expected 'name, 0xADDR, BLOCK, 0xSEG'"),
    ("ok, 0xc000, 0, 0x0000\n    refs.asm 3 x\n", "f:2: expected 'name, 0xADDR, BLOCK, 0xSEG'"),
    ("al C:c000 .ok\nal C:-10 .neg\n", "f:2: expected 'al C:ADDR .name'"),
    ("al C:c000 .ok\nlabel c000 .x\n", "f:2: expected 'al C:ADDR .name'"),
    (".label ok=$c000\n.label bad=$c0zz\n", "f:2: expected '.label name=$ADDR'"),
    ("a.s:1:1: ok = $c000\na.s:2:1: bad = 12abc\n", "f:2: expected 'FILE:LINE:COLUMN: name = $ADDR'"),
])
def test_a_line_no_assembler_writes_is_one_line_naming_file_and_line(text, start):
    with pytest.raises(InputError) as error:
        parse_symbol_file(text, "f")
    assert str(error.value).startswith(start) and "\n" not in str(error.value)


# ---- end to end: a DASM build with every kind of line, through `retro run` and `retro check` --

SPEC = KINDS.parent / "specs" / "boxhit_dasm_kinds.toml"
DASM_NOTE = ("19 symbols read; skipped 2 string macros, 1 string constant, 2 unresolved names, "
             "2 constants outside $0000-$FFFF (lines without an address)")


def run_cli(capsys, *argv) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_retro_run_reads_a_dasm_build_and_says_what_it_skipped(capsys):
    boxes = {"boxa_x": 10, "boxa_y": 20, "boxa_w": 5, "boxa_h": 5, "boxb_x": 14, "boxb_y": 22, "boxb_w": 3, "boxb_h": 3}
    code, out, err = run_cli(capsys, "run", KINDS / "dasm_kinds.prg", "--labels", KINDS / "dasm_kinds.sym",
                             "--entry", "boxhit", *[f"--set={name}={value}" for name, value in boxes.items()])
    lines = out.splitlines()
    assert (code, err) == (0, "")
    assert lines[2][-1] == "1"  # C: the boxes overlap (x 10..14 and 14..16, y 20..24 and 22..24)
    assert lines[-1] == f"note: {KINDS / 'dasm_kinds.sym'}: {DASM_NOTE}"
    assert out.count("skipped") == 1
    # `wait`: LDX #COUNT (the last SET, 4), then the `$` local loop: 2 + 4 * 2 + 3 * 3 + 2 + 6 (RTS) cycles
    code, out, _ = run_cli(capsys, "run", KINDS / "dasm_kinds.prg", "--labels", KINDS / "dasm_kinds.sym",
                           "--entry", "wait", "--peek", "3.done", "--json")
    report = json.loads(out)
    assert code == 0 and (report["x"], report["cycles"], report["peek"]["3.done"]) == (0, 27, [0x60])  # RTS
    assert report["notes"] == [f"{KINDS / 'dasm_kinds.sym'}: {DASM_NOTE}"]  # only when something was skipped


@pytest.mark.parametrize("name", ["PLAYER_Y", "TITLE", "PAL", "DELTA"])
def test_a_skipped_name_is_not_a_label(capsys, name):
    code, out, err = run_cli(capsys, "run", KINDS / "dasm_kinds.prg", "--labels", KINDS / "dasm_kinds.sym",
                             "--entry", name)
    assert code == 2 and out == "" and err.count("\n") == 1 and f"unknown label {name!r}" in err


def test_retro_check_of_a_dasm_build_with_every_line_kind(capsys):
    code, out, err = run_cli(capsys, "check", SPEC, "--quiet")
    lines = out.splitlines()
    assert code == 0 and err == ""
    assert lines[0].startswith("boxhit_dasm_kinds: ") and ", OK; " in lines[0]
    assert lines[1] == f"  note: {KINDS / 'dasm_kinds.sym'}: {DASM_NOTE}"
    code, out, _ = run_cli(capsys, "check", SPEC, "--quiet", "--json")
    assert json.loads(out)[0]["notes"] == [f"{KINDS / 'dasm_kinds.sym'}: {DASM_NOTE}"]


def test_retro_cycles_says_a_shared_symbol_files_note_once(capsys):
    code, out, _ = run_cli(capsys, "cycles", SPEC, SPEC, "--quiet")
    assert code == 0 and out.count("skipped") == 1
    assert out.splitlines()[-1] == f"note: {KINDS / 'dasm_kinds.sym'}: {DASM_NOTE}"


def test_long_hostile_lines_are_read_in_linear_time():
    # a regular expression for xa's reference lines once backtracked quadratically here (27 s at
    # 20,000 numbers): these return at once, a regression hangs
    numbers = "1 " * 100_000
    with pytest.raises(InputError, match="f:2: expected 'name, 0xADDR, BLOCK, 0xSEG'"):
        parse_symbol_file(f"ok, 0xc000, 0, 0x0000\nf {numbers}x\n", "f")
    assert len(parse_symbol_file(f"ok, 0xc000, 0, 0x0000\nf.asm {numbers}\n", "f").symbols) == 1
    with pytest.raises(InputError, match="f:1: expected 'name = \\$ADDR'"):
        parse_symbol_file("x = $1" + " ; ?" * 100_000 + " ; z\n", "f")


def test_dbg_cheap_local_must_hang_off_a_label_and_deep_scopes_are_walked_once():
    head = 'version\tmajor=2,minor=0\nscope\tid=0,name=""\n'
    chained = head + ('sym\tid=0,name="@a",parent=1,val=0xC000,type=lab\n'
                      'sym\tid=1,name="@b",parent=0,val=0xC001,type=lab\n')
    with pytest.raises(InputError, match="t.dbg:3: the parent of this cheap local, symbol 1, is not a label"):
        parse_symbol_file(chained, "t.dbg")
    depth = 5000  # deeper than Python's recursion limit
    scopes = "".join(f'scope\tid={i},name="s{i}",parent={i - 1}\n' for i in range(1, depth))
    syms = "".join(f'sym\tid={i},name="x{i}",scope={depth - 1},val=0x{i:X},type=equ\n' for i in range(200))
    symbols = parse_symbol_file(head + scopes + syms, "t.dbg").symbols
    assert len(symbols) == 200 and symbols[7].scope.count("::") == depth - 2 and symbols[7].address == 7


def test_the_projects_aabb8_built_by_dasm_checks_against_its_reference(capsys):
    # dasm_aabb8.prg is byte for byte `retro asm asm/aabb8.s` (tests/data/symbols/README.md); asm/aabb8.s
    # states its cost as 20-34 cycles, static 20-34
    code, out, _ = run_cli(capsys, "check", KINDS.parent / "specs" / "aabb8_dasm.toml", "--quiet", "--json")
    (record,) = json.loads(out)
    assert code == 0 and record["mismatches"] == 0 and record["cases"] > 3000
    assert (record["static_min"], record["static_max"], record["min"], record["max"]) == (20, 34, 20, 34)
    assert record["notes"] == [f"{KINDS / 'dasm_aabb8.sym'}: 12 symbols read; skipped 1 string macro, "
                               f"1 constant outside $0000-$FFFF (lines without an address)"]
