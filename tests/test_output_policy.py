"""Outputs never over inputs (docs/files.md): every writing command, its outputs pointed at each file
it reads (the files named on its command line and the files those name: a scene's sprites, charset,
screen, CHR and nametable; a source's .include and .incbin; a method's spec, the spec's program,
Python and memory files; a --sprites file, a --script file), directly, through `./`, through `../`, through a
linked folder, as a symbolic link to it and as a hard link to it. Each run must end with exit 2 and
one line, and leave the whole tree byte for byte as it was: no input touched, no output, no temp."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from retro.cli import main
from retro.paths import ASM_DIR

ROOT = Path(__file__).resolve().parents[1]
AABB8_INPUTS = ('ax = "a_x"\nay = "a_y"\naw = "a_w"\nah = "a_h"\nbx = "b_x"\nby = "b_y"\nbw = "b_w"\n'
                'bh = "b_h"\n')


def make_workspace(w: Path) -> dict[str, Path]:
    """Every kind of input a writing command reads, each in its own folder."""
    for folder in ("src", "vic", "nes", "m", "parry", "out"):
        (w / folder / "sub").mkdir(parents=True)
    files = {}
    files["source"] = w / "src" / "a.s"
    files["source"].write_text('        .org $c000\n        .include "inc.s"\nstart:  lda #1\n'
                               '        .incbin "data.bin"\n        rts\n')
    files["include"] = w / "src" / "inc.s"
    files["include"].write_text("helper: nop\n")
    files["incbin"] = w / "src" / "data.bin"
    files["incbin"].write_bytes(b"\x01\x02")

    files["vic scene"] = w / "vic" / "scene.toml"
    files["vic scene"].write_text('chip = "vic-ii"\nvideo = "pal"\n[registers]\n"$d011" = 0x1b\n"$d018" = 0x14\n'
                                  '[[sprite]]\nindex = 0\nx = 100\ny = 100\nfile = "ball.spr"\n'
                                  '[memory]\ncharset = { file = "font.bin" }\nscreen = { file = "screen.bin" }\n')
    shutil.copy(ROOT / "sprites" / "ball.spr", w / "vic" / "ball.spr")
    files["sprite"] = w / "vic" / "ball.spr"
    files["charset"] = w / "vic" / "font.bin"
    files["charset"].write_bytes(bytes(range(256)) * 8)
    files["screen"] = w / "vic" / "screen.bin"
    files["screen"].write_bytes(bytes([1]) * 1000)

    files["nes scene"] = w / "nes" / "scene.toml"
    files["nes scene"].write_text('chip = "nes"\nvideo = "ntsc"\n[ppu]\nmask = 0x1e\n[[oam]]\ny = 25\ntile = 1\n'
                                  'x = 88\n[chr]\nfile = "tiles.chr"\n[[nametable]]\nindex = 0\nfile = "title.nam"\n')
    files["chr"] = w / "nes" / "tiles.chr"
    files["chr"].write_bytes(bytes([0xFF]) * 8192)
    files["nametable"] = w / "nes" / "title.nam"
    files["nametable"].write_bytes(bytes([1]) * 1024)

    files["method"] = w / "m" / "method.toml"
    files["method"].write_text(f'name = "mine"\nroutine = "spec.toml"\n[hitbox]\nshape = "box"\n[inputs]\n{AABB8_INPUTS}')
    spec = (ASM_DIR / "aabb8.toml").read_text().replace('file = "aabb8.s"', 'file = "prog.s"')
    files["spec"] = w / "m" / "spec.toml"
    files["spec"].write_text(spec.replace('"retro.routines.reference:aabb8"', '"ref.py:aabb8"')
                             + '\n[memory]\ntable = { at = "$0400", file = "table.bin" }\n')
    files["memory"] = w / "m" / "table.bin"
    files["memory"].write_bytes(bytes(range(16)))
    files["program"] = w / "m" / "prog.s"
    shutil.copy(ASM_DIR / "aabb8.s", files["program"])
    files["python"] = w / "m" / "ref.py"
    files["python"].write_text("from retro.routines.reference import aabb8\n")

    files["script"] = w / "parry" / "script.txt"
    files["script"].write_text("40:parry\n")
    return files


def snapshot(w: Path) -> dict[str, object]:
    """Every entry under w: a file's bytes, a link's target, a folder's presence."""
    seen: dict[str, object] = {}
    for path in sorted(w.rglob("*")):
        key = str(path.relative_to(w))
        if path.is_symlink():
            seen[key] = ("link", os.readlink(path))
        elif path.is_dir():
            seen[key] = "dir"
        else:
            seen[key] = path.read_bytes()
    return seen


def ways_to_name(w: Path, target: Path, tag: str) -> dict[str, str]:
    """Names of `target` an output could be given: as given, through ./ and ../, through a linked
    folder, a symbolic link to it, a hard link to it (made here, inside w)."""
    linked_folder = w / f"L{tag}"
    linked_folder.symlink_to(target.parent, target_is_directory=True)
    link = w / f"link{tag}{target.suffix}"
    link.symlink_to(target)
    hard = w / f"hard{tag}{target.suffix}"
    os.link(target, hard)
    return {"direct": str(target), "dot": f"{target.parent}/./{target.name}",
            "dotdot": f"{target.parent}/sub/../{target.name}", "linked folder": str(linked_folder / target.name),
            "symlink": str(link), "hard link": str(hard)}


# command -> (the arguments before the output, the output options, the inputs it reads)
FILE_OUTPUTS = {
    "asm": (lambda f: ["asm", str(f["source"])], ["-o", "--labels", "--list"], ["source", "include", "incbin"]),
    "vic": (lambda f: ["vic", str(f["vic scene"])], ["--png"], ["vic scene", "sprite", "charset", "screen"]),
    "nes": (lambda f: ["nes", str(f["nes scene"])], ["--png"], ["nes scene", "chr", "nametable"]),
}


def _file_cases():
    for command, (_, options, inputs) in FILE_OUTPUTS.items():
        for option in options:
            for name in inputs:
                yield pytest.param(command, option, name, id=f"{command} {option} over {name}")


def _refused(capsys, argv: list[str]) -> str:
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, (argv, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


@pytest.mark.parametrize("command, option, name", list(_file_cases()))
def test_a_file_output_never_replaces_an_input(tmp_path, capsys, command, option, name):
    files = make_workspace(tmp_path)
    before_args, _, _ = FILE_OUTPUTS[command]
    ways = ways_to_name(tmp_path, files[name], "x")
    before = snapshot(tmp_path)
    for way, given in ways.items():
        err = _refused(capsys, before_args(files) + [option, given])
        expected = "symbolic link" if way == "symlink" else "is an input of this command"
        assert expected in err, (way, err)
        assert snapshot(tmp_path) == before, way


@pytest.mark.parametrize("command", sorted(FILE_OUTPUTS))
def test_each_file_command_works_on_these_inputs(tmp_path, capsys, command):
    """The control: with an output of its own, each command above succeeds (the refusals are the
    policy's, not a broken fixture's)."""
    files = make_workspace(tmp_path)
    before_args, options, _ = FILE_OUTPUTS[command]
    argv = before_args(files)
    for n, option in enumerate(options):
        argv += [option, str(tmp_path / "out" / f"o{n}")]
    assert main(argv) == 0, capsys.readouterr().err
    assert all((tmp_path / "out" / f"o{n}").is_file() for n in range(len(options)))


def test_two_outputs_of_one_command_on_one_path(tmp_path, capsys):
    files = make_workspace(tmp_path)
    before = snapshot(tmp_path)
    out = tmp_path / "out" / "a"
    for labels in (out, f"{out.parent}/./a", f"{out.parent}/sub/../a"):
        err = _refused(capsys, ["asm", str(files["source"]), "-o", str(out), "--labels", str(labels)])
        assert "the same file" in err and "--labels" in err
        assert snapshot(tmp_path) == before


# Folder commands: their file names are fixed, so the input is put where one of them goes, or the
# output file is made a (symbolic or hard) link to an input.
FOLDER_CASES = {
    "parry script": (["parry", "--frames", "60"], "--script", "script", "parry_events.txt"),
    "chart method": (["chart", "--reduced", "--jobs", "1", "--samples", "2", "--quiet"], "--method", "method",
                     "study.md"),
    "chart sprites": (["chart", "--reduced", "--jobs", "1", "--samples", "2", "--quiet"], "--sprites", "sprite",
                      "study.csv"),
    "stability method": (["stability", "--reduced", "--quiet"], "--method", "method", "stability.md"),
}


@pytest.mark.parametrize("case", sorted(FOLDER_CASES))
def test_a_folder_output_never_replaces_an_input(tmp_path, capsys, case):
    files = make_workspace(tmp_path)
    argv, option, name, output_name = FOLDER_CASES[case]
    out = tmp_path / "out"
    moved = out / output_name  # the input, living where the command writes that output
    files[name].rename(moved)
    if name == "method":  # the method's spec is relative to it
        for other in ("spec", "program", "python", "memory"):
            files[other].rename(out / files[other].name)
    value = ("@" if option == "--script" else "") + str(moved)
    (tmp_path / "Lout").symlink_to(out, target_is_directory=True)
    before = snapshot(tmp_path)
    for given in (out, f"{tmp_path}/./out", f"{out}/sub/..", tmp_path / "Lout"):
        err = _refused(capsys, argv + [option, value, "--out", str(given)])
        assert "is an input of this command" in err, (given, err)
        assert snapshot(tmp_path) == before, given


@pytest.mark.parametrize("case", sorted(FOLDER_CASES))
@pytest.mark.parametrize("link", ["symlink", "hard link"])
def test_a_folder_output_that_is_a_link_to_an_input(tmp_path, capsys, case, link):
    """The output file is a link to one of the files the command reads (for a method: its spec, the
    spec's program, Python file and memory file too)."""
    files = make_workspace(tmp_path)
    argv, option, name, output_name = FOLDER_CASES[case]
    reads = [name] + (["spec", "program", "python", "memory"] if name == "method" else [])
    value = ("@" if option == "--script" else "") + str(files[name])
    for read in reads:
        out = tmp_path / "out" / read.replace(" ", "_")
        out.mkdir()
        if link == "symlink":
            (out / output_name).symlink_to(files[read])
        else:
            os.link(files[read], out / output_name)
        before = snapshot(tmp_path)
        err = _refused(capsys, argv + [option, value, "--out", str(out)])
        assert ("symbolic link" if link == "symlink" else "is an input of this command") in err, (read, err)
        assert snapshot(tmp_path) == before, read


def test_demo_refuses_an_output_that_is_a_link_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "demo"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me\n")
    (out / "demo_sum.prg").symlink_to(victim)
    before = snapshot(tmp_path)
    err = _refused(capsys, ["demo", "--out", str(out)])
    assert "symbolic link" in err
    assert snapshot(tmp_path) == before
