"""A user's method (TOML + routine spec + hitbox rule) and a user's sprites, from the API and the CLI."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import independent as ind
from retro.analysis.study.corpus import SPRITES_DIR, load_shapes, make_pair
from retro.analysis.study.methods import load_methods
from retro.analysis.study.methods.user import load_method_file
from retro.cli import main
from retro.errors import InputError, RunError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "methods"
AABB8_INPUTS = "\n".join(f'{n} = "{v}"' for n, v in [("ax", "a_x"), ("ay", "a_y"), ("aw", "a_w"), ("ah", "a_h"),
                                                      ("bx", "b_x"), ("by", "b_y"), ("bw", "b_w"), ("bh", "b_h")])


def write(tmp_path: Path, text: str, name: str = "m.toml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "retro", *args], capture_output=True, text=True, timeout=300)


def _offsets(pair):
    return list(zip(pair.dx.tolist(), pair.dy.tolist()))


@pytest.fixture(scope="module")
def ball_bar():
    ball, bar = load_shapes(["ball", "bar"])
    return make_pair(ball, bar)


def test_shrunk_box_rule_and_routine(ball_bar):
    """The example: tight boxes 1 px in on every side; the 1-px bar keeps its middle column."""
    m = load_method_file(str(EXAMPLES / "shrunk_box.toml"))
    (ax0, ay0, ax1, ay1), (bx0, by0, bx1, by1) = ind.bounds(ball_bar.a.mask), ind.bounds(ball_bar.b.mask)
    assert (bx1 - bx0, by1 - by0) == (1, 21)
    a, b = (ax0 + 1, ay0 + 1, ax1 - 1, ay1 - 1), (bx0, by0 + 1, bx1, by1 - 1)
    assert (m.verdict(ball_bar) > 0).tolist() == ind.box_hits(a, b, _offsets(ball_bar))
    session = m.session(ball_bar)
    verdict = m.verdict(ball_bar)
    for i in range(0, ball_bar.cases, 13):
        assert session.run(i)[0] == bool(verdict[i])


def test_touching_box_rule(tmp_path, ball_bar):
    m = load_method_file(write(tmp_path, '[hitbox]\nshape = "box"\ntouching = true\n'))
    a, b = ind.bounds(ball_bar.a.mask), ind.bounds(ball_bar.b.mask)
    grown = (b[0] - 1, b[1] - 1, b[2] + 1, b[3] + 1)  # touching counts: as if b were 1 px larger all round
    assert (m.verdict(ball_bar) > 0).tolist() == ind.box_hits(a, grown, _offsets(ball_bar))
    assert m.host_only and m.key == "m"


def test_circle_rules(tmp_path, ball_bar):
    strict = load_method_file(write(tmp_path, '[hitbox]\nshape = "circle"\n', "c.toml"))
    tangent = load_method_file(write(tmp_path, '[hitbox]\nshape = "circle"\ntouching = true\ninset = 2\n', "t.toml"))
    ca, cb = ind.smallest_circle(ball_bar.a.mask), ind.smallest_circle(ball_bar.b.mask)
    assert (strict.verdict(ball_bar) > 0).tolist() == ind.circle_hits(ca, cb, _offsets(ball_bar))
    ta, tb = ind.smallest_circle(ball_bar.a.mask, True), ind.smallest_circle(ball_bar.b.mask, True)
    ta, tb = (ta[0], ta[1], ta[2] - 2), (tb[0], tb[1], tb[2] - 2)
    assert (tangent.verdict(ball_bar) > 0).tolist() == ind.circle_hits(ta, tb, _offsets(ball_bar), tangent_hits=True)


def test_mask_and_function_rules(ball_bar):
    mask = load_method_file(str(EXAMPLES / "exact_mask.toml"))
    assert (mask.verdict(ball_bar) > 0).tolist() == ind.pixel_hits(ball_bar.a.mask, ball_bar.b.mask, _offsets(ball_bar))
    cross = load_method_file(str(EXAMPLES / "cross.toml"))
    verdict = cross.verdict(ball_bar)
    assert verdict.shape == (ball_bar.cases,) and 0 < verdict.sum() < ball_bar.cases
    session = mask.session(ball_bar)
    assert [session.run(i)[0] for i in range(0, ball_bar.cases, 97)] == (mask.verdict(ball_bar)[::97] > 0).tolist()


def test_a_routine_that_does_not_do_the_rule_stops_the_cost_run(tmp_path, ball_bar):
    """The circle routine is strict; a method claiming tangent circles collide is caught on the first
    tangent case (the ball and the bar have some)."""
    from retro.analysis.study.cost_runs import measure_costs

    text = ('routine = "circle"\n[hitbox]\nshape = "circle"\ntouching = true\n[inputs]\n'
            'x1 = "a_cx"\ny1 = "a_cy"\nr1 = "a_r"\nx2 = "b_cx"\ny2 = "b_cy"\nr2 = "b_r"\n')
    wrong = load_method_file(write(tmp_path, text))
    ta, tb = ind.smallest_circle(ball_bar.a.mask, True), ind.smallest_circle(ball_bar.b.mask, True)
    assert ind.tangent_offsets(ta, tb, _offsets(ball_bar))
    with pytest.raises(RunError, match="the rule of method m says True"):
        measure_costs([], samples=None, workers=1, pair_list=[(ball_bar.a, ball_bar.b)], methods=(wrong,))
    right = load_method_file(write(tmp_path, text.replace("touching = true\n", ""), "right.toml"))
    costs = measure_costs([], samples=None, workers=1, pair_list=[(ball_bar.a, ball_bar.b)], methods=(right,))
    assert costs["right"].overall.samples == ball_bar.cases


def test_user_methods_pickle_to_workers():
    import pickle

    m = load_method_file(str(EXAMPLES / "cross.toml"))
    again = pickle.loads(pickle.dumps(m))
    assert again.key == m.key and again.hitbox.function_text == "cross.py:hit"


@pytest.mark.parametrize("text,field", [
    ('[hitbox]\nshape = "blob"\n', "hitbox.shape"),
    ('colour = "#ff0000"\nfoo = 1\n[hitbox]\nshape = "box"\n', "foo"),
    ('[hitbox]\nshape = "box"\nradius = 3\n', "hitbox.radius"),
    ('[hitbox]\nshape = "box"\nfit = "loose"\n', "hitbox.fit"),
    ('[hitbox]\nshape = "box"\ninset = [1, 2]\n', "hitbox.inset"),
    ('[hitbox]\nshape = "circle"\ninset = [1, 2, 3, 4]\n', "hitbox.inset"),
    ('[hitbox]\nshape = "box"\ntouching = "yes"\n', "hitbox.touching"),
    ('name = "box"\n[hitbox]\nshape = "box"\n', "name"),
    ('name = "no spaces"\n[hitbox]\nshape = "box"\n', "name"),
    ('label = "x"\n', "hitbox"),
    ('routine = "nonesuch"\n[hitbox]\nshape = "box"\n', "routine"),
    ('routine = "aabb8"\n[hitbox]\nshape = "box"\n', "inputs"),
    (f'routine = "aabb8"\n[hitbox]\nshape = "box"\n[inputs]\n{AABB8_INPUTS}\nextra = "dx"\n', "inputs.extra"),
    (f'routine = "aabb8"\n[hitbox]\nshape = "box"\n[inputs]\n{AABB8_INPUTS.replace("b_h", "b_height")}\n',
     "inputs.bh"),
    (f'routine = "aabb8"\n[hitbox]\nshape = "box"\n[inputs]\n{AABB8_INPUTS.replace("b_h", "__import__(1)")}\n',
     "inputs.bh"),
    (f'routine = "aabb8"\nhit = "answer"\n[hitbox]\nshape = "box"\n[inputs]\n{AABB8_INPUTS}\n', "hit"),
    ('hit = "hit"\n[hitbox]\nshape = "box"\n', "hit"),
    ('[hitbox]\nshape = "function"\n', "hitbox.function"),
    ('[hitbox]\nshape = "function"\nfunction = "nope.py:hit"\n', "hitbox.function"),
    ('[hitbox]\nshape = "function"\nfunction = "rule.py:missing"\n', "hitbox.function"),
    ('marker = "not a marker"\n[hitbox]\nshape = "box"\n', "marker"),
    ('colour = "not a colour"\n[hitbox]\nshape = "box"\n', "colour"),
    ('[hitbox\n', "not valid TOML"),
])
def test_bad_method_files_are_one_line_naming_file_and_field(tmp_path, text, field, capsys):
    (tmp_path / "rule.py").write_text("def hit(a, b, dx, dy):\n    return dx == dy\n")
    path = write(tmp_path, text)
    with pytest.raises(InputError) as caught:
        load_methods([path])
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"{path}: ") and field in message, message
    assert main(["chart", "--method", path, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and path in err and field in err
    assert not (tmp_path / "out").exists()  # nothing written before the inputs are checked


def test_a_function_that_fails_is_a_one_line_input_error(tmp_path, ball_bar):
    (tmp_path / "bad.py").write_text("def hit(a, b, dx, dy):\n    return [1, 2]\n")
    m = load_method_file(write(tmp_path, '[hitbox]\nshape = "function"\nfunction = "bad.py:hit"\n'))
    with pytest.raises(InputError, match=r"hitbox.function: bad.py:hit returned shape \(2,\) for 1927 offsets"):
        m.verdict(ball_bar)


@pytest.mark.parametrize("body, message", [
    ("import sys; sys.exit(0)", "called sys.exit(0)"),
    ("import os; os._exit(0)", "called os._exit(0)"),
    ("while True: pass", "took more than 1 s"),
    ("return hit(a, b, dx, dy)", "recursed without end"),
    ("raise KeyError('x')", "raised KeyError"),
    ("return 10 ** 5000", "returned an integer of 16610 bits"),
    ("return dx * float('nan')", "returned values outside [0, 1]"),
])
def test_a_rule_that_exits_hangs_or_recurses_is_one_line_naming_it_and_the_pair(tmp_path, ball_bar, body, message):
    (tmp_path / "bad.py").write_text(f"def hit(a, b, dx, dy):\n    {body}\n")
    m = load_method_file(write(tmp_path, '[hitbox]\nshape = "function"\nfunction = "bad.py:hit"\ntime_limit = 1\n'))
    with pytest.raises(InputError) as caught:
        m.verdict(ball_bar)
    text = str(caught.value)
    assert "\n" not in text and "hitbox.function: bad.py:hit" in text and message in text, text
    assert f"on {ball_bar.name}" in text, text


def test_a_rule_module_that_exits_at_import_is_one_line(tmp_path):
    (tmp_path / "bad.py").write_text("import sys\nsys.exit(0)\ndef hit(a, b, dx, dy):\n    return dx * 0\n")
    with pytest.raises(InputError, match=r"hitbox.function: bad.py failed to import: bad.py called sys.exit\(0\)"):
        load_method_file(write(tmp_path, '[hitbox]\nshape = "function"\nfunction = "bad.py:hit"\n'))


def test_a_rules_time_limit_is_checked(tmp_path):
    (tmp_path / "ok.py").write_text("def hit(a, b, dx, dy):\n    return dx * 0\n")
    with pytest.raises(InputError, match=r"hitbox.time_limit: 0 is out of range 1..3600"):
        load_method_file(write(tmp_path, '[hitbox]\nshape = "function"\nfunction = "ok.py:hit"\ntime_limit = 0\n'))


def test_an_input_that_does_not_fit_is_a_run_error(tmp_path, ball_bar):
    text = f'routine = "aabb8"\n[hitbox]\nshape = "box"\n[inputs]\n{AABB8_INPUTS.replace(chr(34) + "b_x", chr(34) + "b_x - 100")}\n'
    m = load_method_file(write(tmp_path, text))
    with pytest.raises(RunError, match=r"inputs.bx: -\d+ does not fit the input's 8 bits"):
        m.session(ball_bar).run(0)


# ---- user sprites ---------------------------------------------------------------------------------

def test_sprites_from_every_format(tmp_path):
    from retro.analysis.study.sprites_io import load_sprite_files
    from retro.render.sprite_png import write_png
    from retro.sprites import read_spr

    ball, ring = read_spr(SPRITES_DIR / "ball.spr"), read_spr(SPRITES_DIR / "ring.spr")
    blank = bytes(63)
    (tmp_path / "two.spr").write_bytes(ball + b"\0" + blank + b"\0" + ring + b"\0")  # a transparent frame between
    (tmp_path / "pad.spd").write_bytes(bytes([0, 1, 2]) + ring + bytes([0x81]) + ball + bytes([0x01]))  # SpritePad 1
    write_png(tmp_path / "one.png", ball)
    scene = tmp_path / "scene.toml"
    scene.write_text(f'chip = "vic-ii"\nvideo = "pal"\n[[sprite]]\nindex = 2\nx = 100\ny = 100\n'
                     f'file = "{SPRITES_DIR / "bar.spr"}"\n')
    shapes = load_sprite_files([str(tmp_path / n) for n in ("two.spr", "pad.spd", "one.png", "scene.toml")],
                               taken={"one"})
    assert [s.name for s in shapes] == ["two.0", "two.2", "pad.0", "pad.1", "one#2", "scene.sprite2"]
    assert [s.multicolor for s in shapes] == [False, False, True, False, False, False]
    assert np.array_equal(shapes[0].mask, load_shapes(["ball"])[0].mask)
    assert np.array_equal(shapes[-1].mask, load_shapes(["bar"])[0].mask)


def test_bad_sprite_files_are_one_line(tmp_path, capsys):
    (tmp_path / "odd.spr").write_bytes(bytes(10))
    (tmp_path / "empty.spr").write_bytes(bytes(64))
    for name, text in (("odd.spr", "64-byte blocks"), ("empty.spr", "transparent"), ("missing.spr", "missing.spr")):
        assert main(["chart", "--sprites", str(tmp_path / name), "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and text in err, err


def test_chart_with_a_user_method_and_sprites_from_the_cli(tmp_path):
    """The example method and a sprite file join a two-shape chart: their rows are in the CSV, the
    user's sprite is paired with every shape."""
    from retro.analysis.study.report import rows_from_csv

    (tmp_path / "extra.spr").write_bytes((SPRITES_DIR / "ship.spr").read_bytes())
    out = tmp_path / "chart"
    done = run_cli("chart", "--reduced", "--method", str(EXAMPLES / "shrunk_box.toml"), "--sprites",
                   str(tmp_path / "extra.spr"), "--samples", "8", "--out", str(out), "--quiet", "--jobs", "2")
    assert done.returncode == 0, done.stderr
    rows = rows_from_csv((out / "study.csv").read_text())
    assert {r.method for r in rows} >= {"shrunk", "tight", "pixel"}
    scopes = {r.scope for r in rows}
    assert {"ball+extra", "extra+extra", "mc_gem+extra"} <= scopes
    shrunk = next(r for r in rows if r.scope == "ALL" and r.method == "shrunk")
    assert shrunk.cycle_samples == 8 * 10 and shrunk.label == "tight box, 1 px in"
    assert "tight box, 1 px in" in done.stdout
    assert "shrunk" in (out / "study.md").read_text()


def test_advise_with_a_user_method(tmp_path):
    done = run_cli("advise", "examples/vic_two_balls.toml", "--accuracy", "0.5", "--method",
                   str(EXAMPLES / "shrunk_box.toml"), "--quiet", "--jobs", "1")
    assert done.returncode == 0, done.stderr
    assert any(line.strip().startswith(("ok tight box, 1 px in", "-- tight box, 1 px in"))
               for line in done.stdout.splitlines()), done.stdout


def test_advise_rejects_a_bad_method_file(tmp_path, capsys):
    path = write(tmp_path, '[hitbox]\nshape = "oval"\n')
    assert main(["advise", "examples/vic_two_balls.toml", "--method", path]) == 2
    assert "hitbox.shape" in capsys.readouterr().err


def test_a_user_method_in_the_stability_study():
    """The shrunk box (1 px in) sees the 4x4 bullet as 2x2: 1 + 2 - 1 positions against a 1 px wall
    shrunk to its middle column, so it misses above 2 px/frame; on two full sprites it says no where
    they share one column (its boxes are 1 px in on each side)."""
    from retro.analysis.study.methods import BUILTIN
    from retro.analysis.study.stability import edges, tunnelling

    shrunk = load_method_file(str(EXAMPLES / "shrunk_box.toml"))
    methods = BUILTIN + (shrunk,)
    bullet = load_shapes(["bullet"])[0]
    rows = tunnelling.tunnelling_table(bullet, speeds=tuple(range(1, 6)), thicknesses=(1,), methods=methods)
    assert tunnelling.safe_speed(rows, "shrunk", 1) == 2
    table = {(r.case, r.test): r.hit for r in edges.edge_table(methods)}
    cases = list(edges.BOX_CASES)
    assert [table[(c, "rule: tight box, 1 px in")] for c in cases] == [0.0, 0.0, 0.0]
    assert [table[(c, "6502 aabb8 (shrunk)")] for c in cases] == [0.0, 0.0, 0.0]


def test_input_expressions_index_the_masks_and_refuse_arithmetic_on_them(tmp_path):
    from retro.routines.where import parse_where
    from retro.analysis.study.methods.user import MASKS, NAMES

    values = list(range(len(NAMES)))
    values[NAMES.index("a_mask")] = tuple(range(100, 163))
    (term,) = parse_where("a_mask[3] + dx", NAMES, "m.toml: inputs.x", MASKS)
    assert term.test(*values) == 103 + values[NAMES.index("dx")]
    with pytest.raises(InputError, match="m.toml: inputs.x: a_mask: arithmetic takes numbers"):
        parse_where("a_mask * 100000000", NAMES, "m.toml: inputs.x", MASKS)
