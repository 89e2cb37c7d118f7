"""Symbol files of ACME, 64tass, ca65/ld65, DASM, xa and Kick Assembler, read from their real output.

Expected addresses come from the assemblers' own listings (tests/data/foreign/*_boxhit.lst, e.g.
acme_boxhit.lst line 38 `c034 18 clc` under `miss`), never from the parser: all five assemblers
produced the same bytes, so every file names the same addresses.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from retro.errors import InputError
from retro.loaders import Symbol, detect_format, parse_symbols, read_symbols, symbol_tables
from retro.loaders.symbols import parse_symbol_file

FOREIGN = Path(__file__).resolve().parent.parent / "data" / "foreign"

# from acme_boxhit.lst / 64tass_boxhit.lst
GLOBALS = {"boxhit": 0xC000, "miss": 0xC034, "fill": 0xC036, "sum": 0xC03F, "boxb_x": 0xC04B, "boxb_y": 0xC04C,
           "boxb_w": 0xC04D, "boxb_h": 0xC04E, "buf": 0xC04F}
ZERO_PAGE = {"boxa_x": 0xFB, "boxa_y": 0xFC, "boxa_w": 0xFD, "boxa_h": 0xFE}
FILL_LOOP, SUM_LOOP = 0xC038, 0xC043

# file -> (format detected, {name the user may type: address}, zero-page equates kept?)
CASES = {
    "acme_boxhit.sym": ("ACME --symbollist / 64tass --labels", {}, True),
    "acme_boxhit.lbl": ("VICE labels", {}, True),
    "64tass_boxhit.labels": ("ACME --symbollist / 64tass --labels", {}, True),
    "64tass_boxhit.vice": ("VICE labels", {"fill::loop": FILL_LOOP, "fill:loop": FILL_LOOP,
                                           "sum::loop": SUM_LOOP, "sum:loop": SUM_LOOP}, False),
    "64tass_boxhit.vicenum": ("VICE labels", {"fill::loop": FILL_LOOP, "sum:loop": SUM_LOOP}, True),
    "64tass_boxhit.dump": ("64tass --dump-labels", {"fill::loop": FILL_LOOP, "fill.loop": FILL_LOOP,
                                                    "sum.loop": SUM_LOOP}, True),
    "ca65_boxhit.lbl": ("VICE labels", {"loop@$C038": FILL_LOOP, "loop@$C043": SUM_LOOP}, True),
    "ca65_boxhit.dbg": ("ca65/ld65 --dbgfile", {"fill::loop": FILL_LOOP, "sum::loop": SUM_LOOP}, True),
    "dasm_boxhit.sym": ("DASM -s", {"1.loop": FILL_LOOP, "1::loop": FILL_LOOP, "2.loop": SUM_LOOP}, True),
    "xa_boxhit.labels": ("xa -l", {"loop@$C038": FILL_LOOP, "loop@$C043": SUM_LOOP}, True),
    "kick_boxhit.sym": ("Kick Assembler .sym", {"fill::loop": FILL_LOOP, "fill.loop": FILL_LOOP,
                                                "sum.loop": SUM_LOOP}, True),
    "kick_boxhit.vs": ("VICE labels", {"fill.loop": FILL_LOOP, "sum::loop": SUM_LOOP}, True),
}
# where each file's two `loop`s leave the bare name (ACME and 64tass --labels leave locals out)
LOOP_CANDIDATES = {
    "64tass_boxhit.vice": ("fill::loop", "sum::loop"),
    "64tass_boxhit.vicenum": ("fill::loop", "sum::loop"),
    "64tass_boxhit.dump": ("fill::loop", "sum::loop"),
    "ca65_boxhit.lbl": ("loop@$C038", "loop@$C043"),
    "ca65_boxhit.dbg": ("fill::loop", "sum::loop"),
    "dasm_boxhit.sym": ("1::loop", "2::loop"),
    "xa_boxhit.labels": ("loop@$C038", "loop@$C043"),
    "kick_boxhit.sym": ("fill::loop", "sum::loop"),
    "kick_boxhit.vs": ("fill::loop", "sum::loop"),
}


@pytest.mark.parametrize("file", sorted(CASES))
def test_each_real_symbol_file_is_detected_and_read(file):
    expected_format, scoped, keeps_zero_page = CASES[file]
    text = (FOREIGN / file).read_text()
    assert detect_format(text).name == expected_format
    table, ambiguous = symbol_tables(read_symbols(FOREIGN / file))
    expected = {**GLOBALS, **scoped, **(ZERO_PAGE if keeps_zero_page else {})}
    assert {name: table.get(name) for name in expected} == expected
    if not keeps_zero_page:
        assert not set(ZERO_PAGE) & set(table)
    if file in LOOP_CANDIDATES:
        assert ambiguous == {"loop": LOOP_CANDIDATES[file]} and "loop" not in table
    else:
        assert ambiguous == {} and "loop" not in table


def test_ld65_linker_symbols_are_read_too():
    table, _ = symbol_tables(read_symbols(FOREIGN / "ca65_boxhit.lbl"))
    assert table["__LOADADDR__"] == 0x0001 and table["__BSS_LOAD__"] == 0xC053


def test_kick_constants_are_kept_and_non_numbers_left_out():
    table, _ = symbol_tables(read_symbols(FOREIGN / "kick_boxhit.sym"))
    assert table["SCREEN_WIDTH"] == 40 and "GREETING" not in table


def test_a_cheap_local_of_ca65_is_scoped_by_its_label():
    text = ('version\tmajor=2,minor=0\n'
            'scope\tid=0,name="",mod=0,size=4\n'
            'sym\tid=0,name="@l",addrsize=absolute,size=1,parent=1,def=4,val=0xC000,seg=0,type=lab\n'
            'sym\tid=1,name="start",addrsize=absolute,scope=0,def=9,val=0xC000,seg=0,type=lab\n'
            'sym\tid=2,name="ext",addrsize=absolute,scope=0,type=imp,exp=1\n')
    assert parse_symbols(text, "t.dbg") == [Symbol("@l", 0xC000, "start"), Symbol("start", 0xC000)]


def test_same_name_at_one_address_in_two_scopes_is_not_ambiguous():
    table, ambiguous = symbol_tables([Symbol("entry", 0x1000, "a"), Symbol("entry", 0x1000, "b")])
    assert table["entry"] == 0x1000 and ambiguous == {}


def test_a_global_beside_scoped_names_is_reached_as_root_qualified():
    table, ambiguous = symbol_tables([Symbol("loop", 0x1000), Symbol("loop", 0x2000, "proc")])
    assert ambiguous == {"loop": ("::loop", "proc::loop")}
    assert (table["::loop"], table["proc::loop"]) == (0x1000, 0x2000) and "loop" not in table


def test_vice_label_spellings_of_every_producer():
    text = "al C:c000 .acme\nal c010 .tass\nal 00C020 .ld65\nal C:c030 .outer.inner\n"
    table, _ = symbol_tables(parse_symbols(text))
    assert table == {"acme": 0xC000, "tass": 0xC010, "ld65": 0xC020, "outer::inner": 0xC030,
                     "outer.inner": 0xC030, "inner": 0xC030}


@pytest.mark.parametrize("text", [
    "al C:c000 .ok\nal 012345 .far\n",
    "ok = $c000\nfar = $12345\n",
    ".label ok=$c000\n.label far=$10000\n",
    "ok, 0xc000, 0, 0x0000\nfar, 0x10000, 0, 0x0000\n",
    "--- Symbol List (sorted by symbol)\nok   c000\nfar   10000   (R )\n--- End of Symbol List.\n",
])
def test_a_constant_above_ffff_is_skipped_and_counted(text):
    symbol_file = parse_symbol_file(text, "f")
    assert symbol_file.symbols == (Symbol("ok", 0xC000),)
    assert symbol_file.note == "f: 1 symbol read; skipped 1 constant outside $0000-$FFFF (lines without an address)"


@pytest.mark.parametrize("text, start", [
    ("al C:c000 .ok\nal C:c0\n", "f:2: expected 'al C:ADDR .name'"),
    (".label ok=$c000\n.namespace fill {\n  .label loop=$c038\n", "f: .namespace fill is not closed"),
    (".label ok=$c000\n}\n", "f:2: '}' closes no .namespace"),
    ("ok = $c000\nthis is not an equate\n", "f:2: expected 'name = $ADDR'"),
])
def test_malformed_and_truncated_files_name_the_line(text, start):
    with pytest.raises(InputError) as error:
        parse_symbols(text, "f")
    assert str(error.value).startswith(start) and "\n" not in str(error.value)


def test_truncated_debug_file_is_caught_by_its_record_counts(tmp_path):
    lines = (FOREIGN / "ca65_boxhit.dbg").read_text().splitlines()
    cut = tmp_path / "cut.dbg"
    cut.write_text("\n".join(lines[:-4]) + "\n")  # the last sym lines (and the type lines) lost
    with pytest.raises(InputError, match=r"cut.dbg: truncated: its info line promises 15 sym records, the file has 13"):
        read_symbols(cut)


def test_unknown_format_lists_the_formats_tried(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("Some notes about the game\n")
    with pytest.raises(InputError) as error:
        read_symbols(path)
    message = str(error.value)
    assert message.startswith(f"{path}: not a symbol file in a known format (tried ")
    for name in ("VICE labels", "Kick Assembler .sym", "ca65/ld65 --dbgfile", "DASM -s", "xa -l",
                 "64tass --dump-labels", "ACME --symbollist / 64tass --labels"):
        assert name in message


def test_binary_junk_is_one_line(tmp_path):
    path = tmp_path / "junk.sym"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(InputError, match=r"junk.sym: not a symbol file \(binary data\)"):
        read_symbols(path)
    high = tmp_path / "high.sym"
    high.write_bytes(bytes(range(0x80, 0x100)))
    with pytest.raises(InputError, match="high.sym: not a symbol file in a known format"):
        read_symbols(high)


def test_empty_symbol_file_has_no_symbols(tmp_path):
    path = tmp_path / "empty.lbl"
    path.write_text("\n\n")
    assert read_symbols(path) == []


def test_nested_ca65_scopes_qualify_with_every_level():
    # ld65 --dbgfile output for `.scope outer` / `.proc inner` / `loop: rts` (ca65 2.19)
    text = ('version\tmajor=2,minor=0\n'
            'scope\tid=0,name="",mod=0,size=4,span=0+4\n'
            'scope\tid=1,name="outer",mod=0,type=scope,size=1,parent=0,span=3\n'
            'scope\tid=2,name="inner",mod=0,type=scope,size=1,parent=1,sym=1,span=3\n'
            'sym\tid=0,name="loop",addrsize=absolute,size=1,scope=2,def=0,val=0xC003,seg=0,type=lab\n'
            'sym\tid=1,name="inner",addrsize=absolute,size=1,scope=1,def=7,val=0xC003,seg=0,type=lab\n')
    table, ambiguous = symbol_tables(parse_symbols(text, "t.dbg"))
    assert table == {"outer::inner::loop": 0xC003, "outer::inner": 0xC003, "loop": 0xC003, "inner": 0xC003}
    assert ambiguous == {}


def test_kick_names_may_carry_their_scopes():
    table, ambiguous = symbol_tables(parse_symbols(".label fill.loop=$c038\n.namespace sum {\n"
                                                   "  .label loop=$c043\n}\n", "k.sym"))
    assert (table["fill.loop"], table["fill::loop"], table["sum::loop"]) == (0xC038, 0xC038, 0xC043)
    assert ambiguous == {"loop": ("fill::loop", "sum::loop")}
