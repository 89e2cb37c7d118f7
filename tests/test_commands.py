"""One function per command (retro.commands), a thin CLI over them, and a demo made of calls to them.

The CLI must print exactly what the command function's result gives, check each argument once (in the
function, so the message is the same from Python and from the shell), and name options the same way
in every command."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import retro.commands
from retro import cli
from retro.analysis.check import engines as check_module
from retro.commands import advise, asm, chart, demo, nes, parry, run, stability, vic
from retro.errors import InputError
from retro.paths import ASM_DIR, EXAMPLES_DIR

COMMANDS = ("demo", "asm", "run", "vic", "nes", "check", "cycles", "chart", "stability", "advise", "parry", "profile",
            "optimize")


def subparsers() -> dict:
    parser = cli.build_parser()
    action = next(a for a in parser._actions if a.dest == "command")
    return action.choices


def test_every_command_is_one_function_in_its_own_module():
    assert set(subparsers()) == set(COMMANDS)
    package = Path(retro.commands.__file__).parent
    assert {p.stem for p in package.glob("*.py")} - {"__init__", "options"} == set(COMMANDS)
    for name in COMMANDS:
        module = __import__(f"retro.commands.{name}", fromlist=[name])
        assert callable(getattr(module, name)), name
        assert cli.command_module(name) is module  # the command whole in its module: options and main beside it
        assert callable(module.add_options) and callable(module.main) and module.HELP, name
        if name != "demo":
            assert callable(module.lines), name


def _actions(parser) -> list[tuple]:
    return [(tuple(a.option_strings), a.dest, a.default, a.nargs, a.choices, a.required, type(a).__name__, a.help)
            for a in parser._actions]


def test_a_command_parses_alike_on_its_own_parser():
    """A run of one command builds only that command's parser (cli.main): its options are the whole parser's."""
    whole = subparsers()
    assert tuple(whole) == cli.COMMANDS  # (the order `retro --help` lists them)
    for name in cli.COMMANDS:
        action = next(a for a in cli.build_parser(name)._actions if a.dest == "command")
        assert list(action.choices) == [name]
        assert _actions(action.choices[name]) == _actions(whole[name]), name


ONE_COMMAND = """
import json, sys
from retro import cli
try:
    cli.main(["cycles", "--help"])
except SystemExit as exc:
    print(json.dumps([exc.code, sorted(m for m in sys.modules if m.startswith("retro.commands."))]))
"""


def test_a_command_imports_only_its_own_module():
    """`retro cycles ...` loads retro.commands.cycles (and the check it is a view of), not the other commands."""
    done = subprocess.run([sys.executable, "-c", ONE_COMMAND], capture_output=True, text=True)
    assert "usage: retro cycles" in done.stdout, done.stderr
    code, loaded = json.loads(done.stdout.strip().splitlines()[-1])
    assert code == 0 and loaded == ["retro.commands.check", "retro.commands.cycles", "retro.commands.options"], loaded


@pytest.mark.parametrize("option", ["--jobs", "--engine", "--quiet", "--method", "--out", "--json", "--scale"])
def test_an_option_means_the_same_in_every_command(option):
    helps = {}
    for name, parser in subparsers().items():
        for action in parser._actions:
            if option in action.option_strings:
                helps[name] = (action.dest, action.choices, action.nargs, type(action).__name__)
    assert len(helps) >= 2 or option == "--scale", helps
    assert len({(dest, tuple(choices or ()), nargs, kind) for dest, choices, nargs, kind in helps.values()}) == 1, helps
    assert not any(option == "--workers" for parser in subparsers().values() for action in parser._actions
                   for option in action.option_strings)


def test_cli_prints_the_command_functions_json(capsys):
    scene = EXAMPLES_DIR / "vic_two_balls.toml"
    assert cli.main(["vic", str(scene), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == json.loads(json.dumps(vic.as_json(vic.vic(scene))))
    nes_scene = EXAMPLES_DIR / "nes_sprite0.toml"
    assert cli.main(["nes", str(nes_scene), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == nes.as_json(nes.nes(nes_scene))
    assert cli.main(["run", str(ASM_DIR / "demo_sum.s"), "--entry", "demo_sum", "--x", "8", "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == run.as_json(run.run(ASM_DIR / "demo_sum.s", "demo_sum", x=8))


def test_cli_prints_the_command_functions_lines(capsys):
    scene = EXAMPLES_DIR / "vic_two_balls.toml"
    assert cli.main(["vic", str(scene)]) == 0
    assert capsys.readouterr().out.splitlines() == vic.lines(vic.vic(scene))
    assert cli.main(["run", str(ASM_DIR / "demo_sum.s"), "--entry", "demo_sum", "--x", "8", "--trace"]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed == run.lines(run.run(ASM_DIR / "demo_sum.s", "demo_sum", x=8, trace=True))
    assert printed[0].startswith("address") and "RTS" in printed[-5]


# (command function call, CLI arguments): the same bad value given both ways gives the same one line
BAD_VALUES = [
    (lambda: vic.vic(EXAMPLES_DIR / "vic_two_balls.toml", frames="0"),
     ["vic", str(EXAMPLES_DIR / "vic_two_balls.toml"), "--frames", "0"], "--frames: '0' is out of range 1..10000"),
    (lambda: vic.vic(EXAMPLES_DIR / "vic_two_balls.toml", scale="9"),
     ["vic", str(EXAMPLES_DIR / "vic_two_balls.toml"), "--scale", "9"], "--scale: '9' is out of range 1..8"),
    (lambda: vic.vic(EXAMPLES_DIR / "vic_two_balls.toml", palette="nes"),
     ["vic", str(EXAMPLES_DIR / "vic_two_balls.toml"), "--palette", "nes"], "--palette: 'nes' is not a C64 palette"),
    (lambda: nes.nes(EXAMPLES_DIR / "nes_sprite0.toml", scale="17"),
     ["nes", str(EXAMPLES_DIR / "nes_sprite0.toml"), "--scale", "17"], "--scale: '17' is out of range 1..16"),
    (lambda: advise.advise(EXAMPLES_DIR / "vic_two_balls.toml", accuracy="101%"),
     ["advise", str(EXAMPLES_DIR / "vic_two_balls.toml"), "--accuracy", "101%"], "--accuracy: '101%' is outside (0, 1]"),
    (lambda: advise.advise(EXAMPLES_DIR / "vic_two_balls.toml", objects="65"),
     ["advise", str(EXAMPLES_DIR / "vic_two_balls.toml"), "--objects", "65"], "--objects: '65' is out of range 1..64"),
    (lambda: chart.chart("unused", jobs="0"), ["chart", "--jobs", "0"], "--jobs: '0' is out of range 1..2"),
    (lambda: chart.chart("unused", samples="many"), ["chart", "--samples", "many"], "--samples: not a number: 'many'"),
    (lambda: parry.parry(frames="0"), ["parry", "--frames", "0"], "--frames: '0' is out of range 1..2000"),
    (lambda: run.run(ASM_DIR / "demo_sum.s", "demo_sum", a="256"),
     ["run", str(ASM_DIR / "demo_sum.s"), "--entry", "demo_sum", "--a", "256"], "--a: '256' is out of range 0..255"),
    (lambda: run.run(ASM_DIR / "demo_sum.s", "demo_sum", flags={"c": "2"}),
     ["run", str(ASM_DIR / "demo_sum.s"), "--entry", "demo_sum", "--c", "2"], "--c: '2' is out of range 0..1"),
    (lambda: retro.commands.check.check(["mul8"], at_line=3), ["check", "mul8", "--at-line", "3"],
     "--at-line and --at-cycle go with --scene"),
]


@pytest.mark.parametrize("call, argv, message", BAD_VALUES, ids=[b[1][0] + " " + b[1][-2] for b in BAD_VALUES])
def test_a_bad_value_is_checked_once_with_the_same_words_from_python_and_the_shell(call, argv, message, capsys, tmp_path,
                                                                                 monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing is written: every check comes before any work
    with pytest.raises(InputError) as raised:
        call()
    assert str(raised.value).startswith(message), str(raised.value)
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err == f"retro {argv[0]}: {raised.value}\n"
    assert list(tmp_path.iterdir()) == []


def test_asm_writes_what_it_reports(tmp_path):
    result = asm.asm(ASM_DIR / "demo_sum.s", output=tmp_path / "d.prg", labels=tmp_path / "d.lbl")
    assert result.written == (tmp_path / "d.prg", tmp_path / "d.lbl")
    prg = (tmp_path / "d.prg").read_bytes()
    assert prg[:2] == bytes([result.program.origin & 0xFF, result.program.origin >> 8])  # PRG: load address first
    assert len(prg) - 2 == len(result.program.code)
    assert asm.lines(result) == [f"{len(result.program.code)} bytes at ${result.program.origin:04X}-"
                                 f"${result.program.origin + len(result.program.code) - 1:04X}, "
                                 f"{len(result.program.symbols)} labels -> {tmp_path / 'd.prg'}, {tmp_path / 'd.lbl'}"]


def test_one_rule_chooses_the_engine():
    rule = check_module.batched
    assert not rule("auto", 255, True, 256) and rule("auto", 256, True, 256)
    assert rule("auto", None, True, 10 ** 9)  # an unknown count (a sweep) takes the batched core
    assert rule("batch", 1, True, 256) and not rule("batch", 10 ** 6, False, 256)  # chips: Machine only
    assert not rule("scalar", 10 ** 9, True, 1)
    with pytest.raises(InputError, match="--engine: 'gpu'"):
        rule("gpu", 1, True, 1)


def test_stability_chart_and_advise_pass_the_chosen_engine_down(monkeypatch, tmp_path):
    seen = []
    monkeypatch.setattr(stability, "run_stability", lambda *a, **k: seen.append(k["engine"]))
    stability.stability(tmp_path, engine="scalar")
    monkeypatch.setattr(chart, "run_chart", lambda *a, **k: seen.append(k["engine"]))
    chart.chart(tmp_path, engine="batch")
    monkeypatch.setattr(advise, "advise_scene", lambda *a, **k: seen.append(k["engine"]))
    advise.advise(EXAMPLES_DIR / "vic_two_balls.toml", engine="scalar")
    assert seen == ["scalar", "batch", "scalar"]
    with pytest.raises(InputError, match="--engine: 'gpu'"):
        chart.chart(tmp_path, engine="gpu")


def test_the_demo_is_the_command_functions(monkeypatch, tmp_path):
    """Every demo step reaches its results through retro.commands: with the command functions
    replaced, the steps fail on the replacement."""
    called = []

    class Called(Exception):
        pass

    def stand_in(name):
        def fake(*args, **kwargs):
            called.append(name)
            raise Called(name)
        return fake

    for module, name in ((asm, "asm"), (run, "run"), (vic, "vic"), (nes, "nes"), (parry, "parry"),
                         (chart, "chart")):
        monkeypatch.setattr(module, name, stand_in(name))
    from retro.commands import cycles
    monkeypatch.setattr(cycles, "cycles", stand_in("cycles"))
    for title, step in demo.STEPS:
        with pytest.raises(Called):
            step(tmp_path)
    assert called == ["asm", "vic", "run", "parry", "nes", "cycles", "chart"]


def test_the_readme_command_table_lists_every_option():
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    rows = {line.split("`")[1].split()[1]: line for line in readme.splitlines() if line.startswith("| `retro ")}
    assert set(rows) == set(COMMANDS)
    for name, parser in subparsers().items():
        for action in parser._actions:
            if not action.option_strings or "--help" in action.option_strings:
                continue
            shown = [f"{option} " for option in action.option_strings] + [f"{option}]" for option in action.option_strings]
            if name == "run" and action.dest in run.SETTABLE_FLAGS:  # listed together: --c/--z/--i/--d/--v/--n
                shown += [f"--{action.dest}/", f"/--{action.dest} "]
            if name == "run" and action.dest in ("a", "x", "y"):
                shown.append("[--a/--x/--y V]")
            assert any(text in rows[name] for text in shown), (name, action.option_strings)
