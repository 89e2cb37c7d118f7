"""The Ophis front end: bytes, origin, symbols, listing, errors, isolation between runs."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from retro.assembler import assemble_file, assemble_text, requested_tables
from retro.errors import InputError

SAMPLE = """\
.org $1234
start:  lda #$01
        sta $d020
loop:   dex
        bne loop
        rts
data:   .byte 1, 2
"""
# Hand-assembled from the 6502 opcode table.
SAMPLE_BYTES = bytes([0xA9, 0x01,        # 1234 LDA #$01
                      0x8D, 0x20, 0xD0,  # 1236 STA $D020
                      0xCA,              # 1239 DEX
                      0xD0, 0xFD,        # 123A BNE $1239
                      0x60,              # 123C RTS
                      0x01, 0x02])       # 123D data


def test_bytes_origin_symbols_and_listing():
    program = assemble_text(SAMPLE)
    assert program.origin == 0x1234
    assert program.code == SAMPLE_BYTES
    assert program.symbols == {"start": 0x1234, "loop": 0x1239, "data": 0x123D}
    assert program.end == 0x1234 + len(SAMPLE_BYTES)
    listing_lines = [line for line in program.listing.splitlines() if line.strip()]
    assert listing_lines[0].split()[:3] == ["1234", "A9", "01"]
    assert any("BNE" in line and line.split()[0] == "123A" for line in listing_lines)


def test_anonymous_and_scope_local_labels_are_left_out():
    program = assemble_text(""".org $1000
.scope
_loop:  dex
        bne _loop
.scend
second:
.scope
_loop:  dey
        bne _loop
*       rts
.scend
""")
    assert program.symbols == {"second": 0x1003}


def test_undocumented_opcodes_assemble():
    program = assemble_text(".org $2000\nlax $10\nsax $11\ndcp $1234\nisb $12,x\nslo ($20),y\nanc #$0f\nsbx #$02\n")
    assert program.code == bytes([0xA7, 0x10, 0x87, 0x11, 0xCF, 0x34, 0x12, 0xF7, 0x12, 0x13, 0x20,
                                  0x0B, 0x0F, 0xCB, 0x02])


def test_an_out_of_range_branch_is_an_error_not_a_branch_plus_jmp(tmp_path):
    source = tmp_path / "far.s"
    source.write_text(".org $c000\nstart:  lda #1\n        beq far\n        .advance $c100\nfar:    rts\n")
    with pytest.raises(InputError) as error:
        assemble_file(source)
    assert str(error.value).startswith(f"{source}:3: ")
    assert "branch" in str(error.value).lower()


def test_syntax_error_is_file_line_message(tmp_path):
    source = tmp_path / "bad.s"
    source.write_text(".org $c000\nstart: lda #1\n        lda (\n        rts\n")
    with pytest.raises(InputError) as error:
        assemble_file(source)
    message = str(error.value)
    assert message.startswith(f"{source}:3: ") and "\n" not in message


MACRO_SOURCE = """.org $c000
.macro twice
        inx
        inx
.macend
start:  `twice
        rts
"""


def test_each_assembly_is_isolated_so_a_macro_can_be_defined_again(tmp_path):
    first = assemble_text(MACRO_SOURCE)
    second = assemble_text(MACRO_SOURCE)
    assert first.code == second.code == bytes([0xE8, 0xE8, 0x60])
    other = tmp_path / "other.s"
    other.write_text(MACRO_SOURCE + "        nop\n")
    assert assemble_file(other).code == bytes([0xE8, 0xE8, 0x60, 0xEA])


def test_file_results_follow_edits(tmp_path):
    source = tmp_path / "edit.s"
    source.write_text(".org $1000\nrts\n")
    assert assemble_file(source).code == bytes([0x60])
    source.write_text(".org $1000\nnop\nrts\n")
    assert assemble_file(source).code == bytes([0xEA, 0x60])


def test_table_requests_and_unknown_table_names(tmp_path):
    assert requested_tables("; retro-tables: a b\n  ;retro-tables: c\nlda #1 ; retro-tables: no\n") == ["a", "b", "c"]
    source = tmp_path / "tables.s"
    source.write_text(".org $c000\n\n; retro-tables: no_such_table\nrts\n")
    with pytest.raises(InputError) as error:
        assemble_file(source)
    assert str(error.value).startswith(f"{source}:3: unknown table 'no_such_table'")


def test_missing_source_is_a_one_line_error(tmp_path):
    with pytest.raises(InputError, match="not found"):
        assemble_file(tmp_path / "absent.s")


def test_console_script_works_by_full_path_from_a_never_activated_venv(tmp_path):
    script = Path(sys.executable).parent / "retro"
    if not script.exists():
        pytest.skip(f"no `retro` console script beside {sys.executable} (package not installed in this env)")
    source = tmp_path / "f.s"
    source.write_text(SAMPLE)
    env = {key: value for key, value in os.environ.items() if key not in ("VIRTUAL_ENV", "PYTHONPATH")}
    env["PATH"] = "/usr/bin:/bin"  # no venv bin directory, no `ophis` on PATH
    done = subprocess.run([str(script), "asm", str(source), "-o", str(tmp_path / "f.prg")],
                          capture_output=True, text=True, env=env, cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "f.prg").read_bytes() == bytes([0x34, 0x12]) + SAMPLE_BYTES


def test_text_sources_include_from_the_working_directory_and_errors_use_their_name(tmp_path, monkeypatch):
    (tmp_path / "values.s").write_text("values: .byte 7, 8\n")
    monkeypatch.chdir(tmp_path)
    program = assemble_text('.org $1000\nlda values\n.include "values.s"\n')
    assert program.code == bytes([0xAD, 0x03, 0x10, 7, 8]) and program.symbols == {"values": 0x1003}
    with pytest.raises(InputError, match="^snippet.s:2: "):
        assemble_text(".org $1000\nlda (\n", name="snippet.s")


def test_code_running_past_ffff_is_an_error_naming_the_source(tmp_path):
    # 20 bytes from $FFF0 would end at $10003: no 6502 can hold them, and the PRG would not load.
    source = tmp_path / "wrap.s"
    source.write_text(".org $fff0\n.byte " + ", ".join(["1"] * 20) + "\n")
    with pytest.raises(InputError, match=r"wrap\.s:2: code or data at \$10000, past \$FFFF"):
        assemble_file(source)
    # exactly up to $FFFF is fine
    source.write_text(".org $fff0\n.byte " + ", ".join(["1"] * 16) + "\n")
    assert assemble_file(source).end == 0x10000


# ---- the disk cache of assembled programs ---------------------------------------------------------

def _fresh_process(monkeypatch) -> list:
    """Forget the in-process cache (as a new process would) and count the assembler processes started."""
    from retro import assembler

    assembler._assemble_cached.cache_clear()
    started = []
    real = subprocess.run
    monkeypatch.setattr(assembler.subprocess, "run", lambda *a, **k: started.append(a) or real(*a, **k))
    return started


def _included_source(tmp_path: Path) -> Path:
    (tmp_path / "values.s").write_text("values: .byte 7, 8\n")
    source = tmp_path / "main.s"
    source.write_text('.org $1000\nlda values\nrts\n.include "values.s"\n\n; retro-tables: sq_lo\n')
    return source


def test_a_program_assembled_once_is_read_from_the_disk_cache_in_a_later_process(tmp_path, monkeypatch):
    from retro.fileio import recording_reads

    monkeypatch.setenv("RETRO_CACHE", str(tmp_path / "cache"))
    source = _included_source(tmp_path)
    started = _fresh_process(monkeypatch)
    first = assemble_file(source)
    assert len(started) == 1 and len(list((tmp_path / "cache" / "assembled").glob("*.json"))) == 1
    started = _fresh_process(monkeypatch)
    with recording_reads() as reads:
        again = assemble_file(source)
    assert started == []  # no assembler process: the stored program
    assert again == first and again.code[:4] == bytes([0xAD, 0x04, 0x10, 0x60])
    assert again.symbols["values"] == 0x1004 and "sq_lo" in again.symbols
    # the include is still an input of the command (no output may replace it), as when Ophis read it
    assert any(shown == f"included file {tmp_path / 'values.s'}" for _, shown, _ in reads)


def test_an_include_edited_since_is_assembled_again(tmp_path, monkeypatch):
    monkeypatch.setenv("RETRO_CACHE", str(tmp_path / "cache"))
    source = _included_source(tmp_path)
    _fresh_process(monkeypatch)
    assert assemble_file(source).code[4:6] == bytes([7, 8])
    (tmp_path / "values.s").write_text("values: .byte 9, 10, 11\n")
    started = _fresh_process(monkeypatch)
    assert assemble_file(source).code[4:7] == bytes([9, 10, 11])
    assert len(started) == 1
    source.write_text(source.read_text().replace("lda values", "ldx values"))  # the source itself: a new entry
    assert assemble_file(source).code[0] == 0xAE


def test_a_damaged_or_foreign_cache_entry_is_assembled_again_and_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv("RETRO_CACHE", str(tmp_path / "cache"))
    source = _included_source(tmp_path)
    _fresh_process(monkeypatch)
    first = assemble_file(source)
    (entry,) = (tmp_path / "cache" / "assembled").glob("*.json")
    stored = entry.read_text()
    for damaged in ("{not json", "[]", stored.replace('"key": "', '"key": "0'), stored.replace('"origin": 4096', '"origin": "x"')):
        entry.write_text(damaged)
        started = _fresh_process(monkeypatch)
        assert assemble_file(source) == first and len(started) == 1
        assert entry.read_text() == stored


def test_an_unwritable_cache_is_no_error(tmp_path, monkeypatch):
    (tmp_path / "cache").write_text("a file where the cache folder would be")
    monkeypatch.setenv("RETRO_CACHE", str(tmp_path / "cache"))
    _fresh_process(monkeypatch)
    assert assemble_file(_included_source(tmp_path)).code[:4] == bytes([0xAD, 0x04, 0x10, 0x60])
