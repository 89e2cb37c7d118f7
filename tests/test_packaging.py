"""A non-editable install works: the wheel carries the routines, specs, scenes and sprites.

Builds the wheel from this checkout, installs it into a fresh folder (its dependencies are the
ones this interpreter already has), and runs `retro demo` and `retro check aabb8` from another
folder, so nothing can be read from the repository by accident.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(command: list[str], cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, timeout=300)


def test_wheel_runs_demo_and_check(tmp_path):
    # a clean copy: an earlier build's build/ folder could otherwise supply files the build forgets
    source = tmp_path / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".git", ".venv", "v", "build", "*.egg-info",
                                                                 "__pycache__", ".pytest_cache", ".hypothesis",
                                                                 "retro-out", "out"))
    wheels = tmp_path / "wheels"
    built = _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(wheels),
                  str(source)], cwd=tmp_path)
    assert built.returncode == 0, built.stderr[-2000:]
    # the distribution is "retro-collision" (PyPI's "retro" is another project); the import name stays retro
    (wheel,) = wheels.glob("retro_collision-*.whl")
    target = tmp_path / "site"
    installed = _run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target), str(wheel)],
                     cwd=tmp_path)
    assert installed.returncode == 0, installed.stderr[-2000:]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(target)}
    where = _run([sys.executable, "-c", "import retro, retro.paths as p; print(retro.__file__); print(p.ASM_DIR)"],
                 cwd=elsewhere, env=env)
    assert where.stdout.splitlines() == [str(target / "retro" / "__init__.py"), str(target / "retro" / "_data" / "asm")]
    demo = _run([sys.executable, "-m", "retro", "demo", "--out", str(elsewhere / "out")], cwd=elsewhere, env=env)
    assert demo.returncode == 0, demo.stderr[-2000:]
    assert (elsewhere / "out" / "vic_two_balls.png").is_file() and (elsewhere / "out" / "routine_cycles.json").is_file()
    check = _run([sys.executable, "-m", "retro", "check", "aabb8"], cwd=elsewhere, env=env)
    assert check.returncode == 0 and check.stdout.startswith("aabb8: 3808 cases, OK"), check.stdout + check.stderr
    # the pytest plugin comes with the wheel: its entry point loads it with no -p, from the installed copy
    (entry_points,) = target.glob("retro_collision-*.dist-info/entry_points.txt")
    assert "[pytest11]\nretro.pytest_plugin = retro.pytest_plugin" in entry_points.read_text()
    specs = elsewhere / "specs"
    shutil.copytree(ROOT / "examples" / "rows_only", specs, ignore=shutil.ignore_patterns("*.py", "__pycache__"))
    (elsewhere / "pytest.ini").write_text("[pytest]\nretro_specs = specs/*.toml\n")
    collected = _run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-v", "specs"], cwd=elsewhere, env=env)
    assert collected.returncode == 0 and "specs/mulshift.toml::mulshift PASSED" in collected.stdout, collected.stdout
