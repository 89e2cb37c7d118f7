"""The three commands: exit codes, one-line errors, and what the stability and advice outputs say."""

from __future__ import annotations

import subprocess
import sys

import pytest

from retro.cli import main


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "retro", *args], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("args,field", [
    (["advise", "no-such-scene.toml"], "no-such-scene.toml"),
    (["advise", "examples/vic_two_balls.toml", "--accuracy", "1.5"], "--accuracy"),
    (["advise", "examples/vic_two_balls.toml", "--accuracy", "most"], "--accuracy"),
    (["advise", "examples/nes_8x16_left_clip.toml"], "oam"),  # one sprite on screen: no pair
    (["advise", "examples/vic_two_balls.toml", "--objects", "65"], "--objects"),
    (["advise", "examples/vic_two_balls.toml", "--objects", "0"], "--objects"),
    (["advise", "sprites/ball.spr"], "sprites/ball.spr"),
    (["chart", "--jobs", "0"], "--jobs"),
])
def test_bad_input_is_one_line_and_exit_2(args, field, capsys):
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and field in err and "Traceback" not in err


def test_advise_two_sprite_scene(tmp_path):
    scene = tmp_path / "pair.toml"
    from retro.analysis.study.corpus import SPRITES_DIR

    scene.write_text(f"""chip = "vic-ii"
video = "pal"
[[sprite]]
index = 0
x = 100
y = 100
file = "{SPRITES_DIR / 'ball.spr'}"
[[sprite]]
index = 3
x = 130
y = 100
file = "{SPRITES_DIR / 'bar.spr'}"
""")
    done = run_cli("advise", str(scene), "--accuracy", "0.9", "--quiet", "--jobs", "1")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    advice = next(line for line in lines if line.startswith("advice:"))
    # Two sprites: the latch is exact and the cheapest measured method; then the tight box tested from
    # prepared edges (aabb_edges), whose preparation per object is named beside it.
    assert "VIC-II latch" in advice
    assert any(line.startswith("runner-up: tight hitbox, prepared edges") for line in lines), lines
    assert any("aabb_edges_prepare once per object" in line for line in lines), lines


def test_advise_many_sprites_excludes_the_latch():
    done = run_cli("advise", "examples/vic_two_balls.toml", "--accuracy", "99%", "--quiet", "--jobs", "1")
    assert done.returncode == 0, done.stderr
    assert "cannot say which pair" in done.stdout
    advice = next(line for line in done.stdout.splitlines() if line.startswith("advice:"))
    assert "software pixel-perfect" in advice  # the only exact software method


def test_stability_reduced(tmp_path):
    from retro.analysis.study.stability.run import run_stability

    output = run_stability(tmp_path, reduced=True)
    names = {p.name for p in output.files}
    assert {"tunnelling.png", "wrap.png", "stability.md", "latch_pitfalls.csv", "edges.csv"} <= names
    report = (tmp_path / "stability.md").read_text()
    for kind in ("misattributed", "missed", "late", "false pairs"):
        assert kind in report


def test_range_search_on_the_assembly():
    """Inside each stated domain the assembly is never wrong; the circle's r1 + r2 <= 255 condition is
    shown to be needed (the search finds wrong answers outside it) rather than assumed."""
    from retro.analysis.study.stability.ranges import range_rows

    rows = range_rows(reduced=True)
    assert {r.routine for r in rows} >= {"aabb8", "aabb_sprite", "circle", "mul8", "tile", "tile_box", "pixel"}
    for r in rows:
        assert 0 <= r.wrong <= r.cases
        if r.searched.startswith("inside"):
            assert r.cases > 0 and r.wrong == 0, r
    circle_outside = [r for r in rows if r.routine == "circle" and r.searched.startswith("cases breaking")]
    assert circle_outside and all(r.wrong > 0 for r in circle_outside), circle_outside