"""Checks in one process (a notebook, the pytest plugin) cache a routine's runner and its spec; a
file edited between two checks (the scene, the spec's program) is read again, never run stale."""

from __future__ import annotations

import json
import os
from pathlib import Path

from retro.cli import main
from retro.fileio import cached_reads, read_bytes

FAST = ["--jobs", "1", "--random", "0", "--no-search"]


def _edit(path: Path, text: str) -> None:
    """Rewrite a file as an editor would, its modification time moved on (a clock tick may be
    coarser than the time between two writes in a test)."""
    before = path.stat().st_mtime_ns
    path.write_text(text)
    os.utime(path, ns=(before + 1_000_000_000, before + 1_000_000_000))


def _stolen_max(capsys, scene: Path) -> int:
    code = main(["cycles", "aabb8", "--scene", str(scene), "--at-line", "51", "--json", *FAST])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)[0]["raster"]["scene"]["stolen_max"]


def test_a_scene_edited_between_two_checks_is_read_again(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text('chip = "vic-ii"\nvideo = "pal"\n[registers]\n"$d011" = 0x1b\n')
    # raster line 51 with DEN on and YSCROLL 3 is a Bad Line: the VIC-II takes 40 cycles and the
    # three before them (the CPU stops at its first read) from the call entered at its cycle 1
    assert _stolen_max(capsys, scene) == 43
    _edit(scene, 'chip = "vic-ii"\nvideo = "pal"\n[registers]\n"$d011" = 0x0b\n')  # DEN off, the same size
    assert _stolen_max(capsys, scene) == 0


def _check(capsys, spec: Path) -> int:
    code = main(["check", str(spec), *FAST])
    capsys.readouterr()
    return code


def test_a_specs_program_edited_between_two_checks_is_read_again(tmp_path, capsys):
    (tmp_path / "inc.s").write_text(".org $c000\ninc:    cld\n        clc\n        adc #1\n        rts\n")
    (tmp_path / "inc_ref.py").write_text("def f(a):\n    return (a + 1) & 0xFF\n")
    spec = tmp_path / "inc.toml"
    spec.write_text('[program]\nfile = "inc.s"\nentry = "inc"\n[inputs]\na = "A"\n[outputs]\nr = "A"\n'
                    '[reference]\nfunction = "inc_ref.py:f"\n[cases]\nexhaustive = ["a"]\n')
    assert _check(capsys, spec) == 0
    _edit(tmp_path / "inc.s", ".org $c000\ninc:    cld\n        clc\n        adc #2\n        rts\n")  # the spec unchanged
    assert _check(capsys, spec) == 1


def test_a_cached_answer_is_kept_while_its_files_are_unchanged(tmp_path):
    calls = []

    @cached_reads(maxsize=4)
    def length(path: str) -> int:
        calls.append(path)
        return len(read_bytes(path))

    data = tmp_path / "data.bin"
    data.write_bytes(b"abc")
    assert (length(str(data)), length(str(data))) == (3, 3) and len(calls) == 1
    _edit(data, "abcd")
    assert length(str(data)) == 4 and len(calls) == 2
    assert length(str(data)) == 4 and len(calls) == 2
    data.unlink()
    data.write_bytes(b"xyzw")  # a new file of the same size in its place
    os.utime(data, ns=(0, 0))
    assert length(str(data)) == 4 and len(calls) == 3
