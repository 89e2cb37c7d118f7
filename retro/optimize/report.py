"""What `retro optimize` shows and writes, as plain data and text: the before/after cost table, the
diff of the two listings, the proof record and a spec for the new routine (TOML)."""

from __future__ import annotations

import difflib
import json
import os
from pathlib import Path

from retro import fileio
from retro.analysis.raster import TIMELINES, raster_figures

# [section] keys whose value names a file beside the spec (FILE or FILE.py:FUNCTION)
_FILE_KEYS = {("reference", "function"), ("cases", "boundary"), ("cases", "sweep"), ("cases", "random_generator")}


def cost_row(worst, mean, best, size: int, machine: str, tables: int = 0) -> dict:
    """`size`: the code's bytes; `tables`: those of the allowed tables it reads, counted in "bytes"."""
    return {"worst": worst, "mean": None if mean is None else round(mean, 2), "best": best, "bytes": size + tables,
            "table_bytes": tables, "raster": raster_figures(machine, best, mean, worst)}


def cost_table(before: dict, after: dict, machine: str) -> list[str]:
    rows = [("worst cycles", "worst"), ("mean cycles", "mean"), ("best cycles", "best"), ("bytes", "bytes")]
    lines = [f"{'':<14}{'before':>10}{'after':>10}"]
    if before.get("table_bytes") or after.get("table_bytes"):
        rows.append(("of them tables", "table_bytes"))
    for label, key in rows:
        lines.append(f"{label:<14}{_show(before[key]):>10}{_show(after[key]):>10}")
    for timeline in TIMELINES.get(machine, ()):
        b, a = before["raster"][timeline.key]["max_lines"], after["raster"][timeline.key]["max_lines"]
        lines.append(f"{'lines ' + timeline.key:<14}{_show(b):>10}{_show(a):>10}")
    return lines


def _show(value) -> str:
    return "-" if value is None else f"{value:.2f}" if isinstance(value, float) else str(value)


def listing_diff(before: list[str], after: list[str], name: str) -> list[str]:
    return list(difflib.unified_diff(before, after, f"{name} (before)", f"{name} (after)", lineterm="", n=2))


def _relocated(value: str, spec_dir: Path, out_dir: Path) -> str:
    """A spec's file reference (FILE or FILE.py:FUNCTION) written relative to the new spec's folder."""
    file, sep, function = value.partition(":")
    if not sep or not file.endswith(".py") or Path(file).is_absolute():
        if sep and not file.endswith(".py"):
            return value  # MODULE:FUNCTION
        if not sep and (spec_dir / file).exists():
            return os.path.relpath(spec_dir / file, out_dir)
        return value
    return f"{os.path.relpath(spec_dir / file, out_dir)}:{function}"


def new_spec(doc: dict, spec_dir: Path, out_dir: Path, program_name: str, labels_name: str, name: str) -> dict:
    """The spec of the new routine: the old one's conventions, its program the new PRG and labels,
    every file it names relative to the new spec's folder."""
    doc = json.loads(json.dumps(doc))  # a deep copy of plain TOML data
    doc["name"] = name
    program = doc.setdefault("program", {})
    for key in ("listing", "load", "symbols"):
        program.pop(key, None)
    program["file"] = program_name
    program["symbols"] = labels_name
    for (section, key) in _FILE_KEYS:
        if isinstance(doc.get(section), dict) and isinstance(doc[section].get(key), str):
            doc[section][key] = _relocated(doc[section][key], spec_dir, out_dir)
    for block in (doc.get("memory") or {}).values():
        if isinstance(block, dict):
            for key in ("file", "generator"):
                if isinstance(block.get(key), str):
                    block[key] = _relocated(block[key], spec_dir, out_dir)
    return doc


def toml_text(doc: dict) -> str:
    """TOML for a spec document (scalars and inline tables inside sections, as specs are written)."""
    return fileio.toml_text(doc, tables=1)
