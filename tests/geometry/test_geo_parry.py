"""The parry pipeline: event sequences for given scripts, checked against an independent replay of
the recorded frames (shapely for contact, box arithmetic for the padded window), plus the CLI."""

from __future__ import annotations

from dataclasses import replace

import pytest
import shapely
from PIL import Image
from shapely.geometry import Polygon

from retro.cli import main
from retro.errors import InputError
from retro.commands.parry import DEFAULT_SCRIPT, parse_script
from retro.geometry.parry import DEFAULT_FRAMES, ParryParams, events_of, simulate

PARAMS = ParryParams()


def play(script: str, frames: int, params: ParryParams = ParryParams()):
    """The simulation under a script in the text format of `retro parry`."""
    return simulate(parse_script(script), frames, params)


def kinds(states):
    return [e.kind for e in events_of(states)]


def first_frame(states, test):
    return next(s.frame for s in states if test(s))


def padded_overlap(s, pad):
    """Recomputed from the recorded vertices: player's box grown by pad vs the enemy's box."""
    px0, py0, px1, py1 = Polygon(s.player).bounds
    ex0, ey0, ex1, ey1 = Polygon(s.enemy).bounds
    return px0 - pad < ex1 and ex0 < px1 + pad and py0 - pad < ey1 and ey0 < py1 + pad


def touching_interiors(s):
    return bool(shapely.relate_pattern(Polygon(s.player), Polygon(s.enemy), "T********"))


@pytest.fixture(scope="module")
def idle():
    return play("", 100)


def test_no_input_means_window_then_hit(idle):
    opened = first_frame(idle, lambda s: padded_overlap(s, PARAMS.pad))
    contact = first_frame(idle, touching_interiors)
    assert opened < contact < opened + PARAMS.window_frames  # the attack lands inside the window
    assert [(e.frame, e.kind) for e in events_of(idle)[:2]] == [(opened, "window"), (contact, "hit")]


def test_press_inside_window_parries(idle):
    opened = next(e.frame for e in events_of(idle) if e.kind == "window")
    contact = next(e.frame for e in events_of(idle) if e.kind == "hit")
    for press in (opened, contact):  # first frame of the window, and the contact frame itself
        states = play(f"{press}:parry", 100)
        assert [(e.frame, e.kind) for e in events_of(states)[:3]] == [
            (opened, "window"), (press, "press"), (contact, "parry")]


def test_press_before_window_is_a_whiff_then_hit(idle):
    opened = next(e.frame for e in events_of(idle) if e.kind == "window")
    contact = next(e.frame for e in events_of(idle) if e.kind == "hit")
    states = play(f"{opened - 1}:parry", 100)
    assert [(e.frame, e.kind) for e in events_of(states)[:3]] == [
        (opened - 1, "whiff"), (opened, "window"), (contact, "hit")]


def test_window_lasts_exactly_n_frames(idle):
    opened = next(e.frame for e in events_of(idle) if e.kind == "window")
    contact = next(e.frame for e in events_of(idle) if e.kind == "hit")
    just_enough = replace(PARAMS, window_frames=contact - opened + 1)  # contact on the last window frame
    states = play(f"{opened}:parry", 100, just_enough)
    assert kinds(states)[:3] == ["window", "press", "parry"]
    too_short = replace(PARAMS, window_frames=contact - opened)  # window closes the frame before
    states = play(f"{opened}:parry", 100, too_short)
    assert [(e.frame, e.kind) for e in events_of(states)[:4]] == [
        (opened, "window"), (opened, "press"), (contact - 1, "expired"), (contact, "hit")]


def test_knockback_separates_along_the_mtv(idle):
    contact = next(e.frame for e in events_of(idle) if e.kind == "hit")
    axis, depth = idle[contact].contact
    assert depth > 0
    # The player was pushed along the axis: afterwards the bodies do not overlap.
    assert not touching_interiors(idle[contact + 1])
    assert axis[0] < 0  # the enemy comes from the right, so the player is pushed left


def test_default_script_shows_every_event():
    assert set(kinds(play(DEFAULT_SCRIPT, DEFAULT_FRAMES))) == {"window", "press", "whiff", "parry", "hit", "expired"}


def test_script_parsing():
    assert parse_script("30:parry, 10:LEFT\n $14:stop # comment") == [(10, "left"), (20, "stop"), (30, "parry")]
    with pytest.raises(InputError, match="unknown action 'jump'"):
        parse_script("10:jump")
    with pytest.raises(InputError, match="expected FRAME:ACTION"):
        parse_script("parry")
    with pytest.raises(InputError, match=r"s.txt:2: 'x:parry': frame: not a number"):
        parse_script("1:parry\nx:parry", "s.txt")
    with pytest.raises(InputError, match="outside 0..9"):
        play("10:parry", 10)


def test_cli_writes_gif_and_pngs(tmp_path, capsys):
    out = tmp_path / "parry"
    assert main(["parry", "--out", str(out), "--frames", "70", "--script", "55:parry"]) == 0
    printed = capsys.readouterr().out
    assert "parry" in printed and "window" in printed
    with Image.open(out / "parry.gif") as gif:
        assert gif.n_frames == 70
    assert len(list(out.glob("parry_*_*.png"))) >= 2
    lines = (out / "parry_events.txt").read_text().splitlines()
    assert [line.split()[1] for line in lines] == kinds(play("55:parry", 70))


def test_cli_bad_input_is_one_line(tmp_path, capsys):
    assert main(["parry", "--out", str(tmp_path), "--script", "5:dance"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown action 'dance'" in err
    assert main(["parry", "--out", str(tmp_path), "--script", "@" + str(tmp_path / "missing.txt")]) == 2
    assert "not found" in capsys.readouterr().err


def test_built_in_script_is_cut_to_the_frames_asked_for(tmp_path):
    from retro.cli import main

    assert main(["parry", "--frames", "100", "--out", str(tmp_path / "p")]) == 0
    events = (tmp_path / "p" / "parry_events.txt").read_text().split()
    frames = [int(token) for token in events[::2]]
    assert frames and max(frames) < 100
