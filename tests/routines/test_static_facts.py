"""The static bounds beside a scene (CPU cycles, said so) and the facts a spec states ([facts])."""

from __future__ import annotations

import json

from retro.cli import main

SCENE = "examples/vic_two_balls.toml"


def test_with_a_scene_the_static_bounds_say_they_count_cpu_cycles_only(capsys):
    assert main(["check", "--scene", SCENE, "aabb8", "--jobs", "1", "--json"]) == 0
    (record,) = json.loads(capsys.readouterr().out)
    # measured with stalls above the static worst, CPU-only within it: compared like with like
    assert record["max"] > record["static_max"] == record["cpu_max"] == 34
    assert record["cpu_min"] == record["static_min"] == 20 and record["bounds_violations"] == []
    assert main(["check", "--scene", SCENE, "aabb8", "--jobs", "1"]) == 0
    headline = capsys.readouterr().out.splitlines()[0]
    assert "CPU 20-34 without the cycles the chip stole, static 20-34 CPU cycles (stolen cycles not included)" in headline
