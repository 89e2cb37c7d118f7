"""Generated routine sources stay equal to their generators (asm/generate/*.py), so they can't drift."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from types import ModuleType

import pytest

from retro.paths import ASM_DIR, PROJECT_ROOT

GENERATOR = ASM_DIR / "generate" / "aabb_sprite.py"


@pytest.fixture(scope="module")
def generator() -> ModuleType:
    """The generator script loaded in-process (asm/generate is a folder of scripts, not a package)."""
    spec = importlib.util.spec_from_file_location("asm_generate_aabb_sprite", GENERATOR)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while the class is built
    spec.loader.exec_module(module)
    return module


def test_aabb_sprite_source_is_its_generators_output(generator):
    on_disk = (ASM_DIR / "aabb_sprite.s").read_text(encoding="utf-8")
    assert generator.generate() == on_disk, "asm/aabb_sprite.s differs: run python asm/generate/aabb_sprite.py"


def test_check_flag_reports_a_stale_file(generator, tmp_path, monkeypatch):
    stale = tmp_path / "aabb_sprite.s"
    stale.write_text(generator.generate().replace("sbc ox1", "sbc oy1", 1), encoding="utf-8")
    monkeypatch.setattr(generator, "OUTPUT", stale)
    assert generator.main(["--check"]) == 1
    stale.write_text(generator.generate(), encoding="utf-8")
    assert generator.main(["--check"]) == 0


def test_output_does_not_depend_on_hash_seed():
    # Another process with another string-hash seed must generate the same file (no set order leaks in).
    env = dict(os.environ, PYTHONHASHSEED="12345")
    run = subprocess.run([sys.executable, str(GENERATOR), "--check"], check=False, cwd=PROJECT_ROOT, env=env,
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr


def test_branch_range_fix_at_the_reach_limit(generator):
    # A branch reaches 127 bytes past its own end (2 bytes): 42 JMPs (126 bytes) + CLC (1) is the limit.
    op, line = generator._op, generator.Line
    in_reach = [op("bcc", "far"), *[op("jmp", "far")] * 42, op("clc"), line(label="far")]
    assert generator.fix_branch_range(in_reach) == (in_reach, 0)
    # One byte more and it becomes BCS around a JMP.
    too_far = [op("bcc", "far"), *[op("jmp", "far")] * 42, op("clc"), op("clc"), line(label="far")]
    fixed, detours = generator.fix_branch_range(too_far)
    assert detours == 1
    assert [(ln.label, ln.mnemonic, ln.operand) for ln in fixed[:3]] == [
        (None, "bcs", "_t1"), (None, "jmp", "far"), ("_t1", None, None)]
