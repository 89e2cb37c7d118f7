"""In a notebook a scene, a check, a profile and a trace show themselves: Jupyter calls `_repr_png_`
(an image) and `_repr_html_` (the report as text) on the value of a cell."""

from __future__ import annotations

import io

from PIL import Image

from retro.commands import nes, profile, run, vic
from retro.paths import ASM_DIR, EXAMPLES_DIR
from retro.testing import check


def png_size(data: bytes) -> tuple[int, int]:
    return Image.open(io.BytesIO(data)).size


def test_a_vic_scene_shows_its_overlap_picture_and_report():
    shown = vic.vic(EXAMPLES_DIR / "vic_two_balls.toml")
    assert png_size(shown._repr_png_())[0] > 300
    assert "$D01E" in shown._repr_html_() and shown._repr_html_().startswith("<pre>")


def test_a_nes_scene_shows_its_picture():
    shown = nes.nes(EXAMPLES_DIR / "nes_sprite0.toml")
    assert png_size(shown._repr_png_())[0] >= 256 and "sprite" in shown._repr_html_().lower()


def test_a_check_shows_its_report():
    report = check(ASM_DIR / "mul8.toml", random=50)
    html = report._repr_html_()
    assert html.startswith("<pre>") and "mul8:" in html and "OK" in html


def test_a_profile_shows_its_table_and_picture():
    shown = profile.profile(EXAMPLES_DIR / "raster_irq_250.s", entry="main", scene=EXAMPLES_DIR / "raster_irq_250.toml")
    assert "irq (IRQ)" in shown._repr_html_()
    assert png_size(shown._repr_png_())[1] >= 312 * 2


def test_a_traced_call_shows_its_listing():
    shown = run.run(EXAMPLES_DIR / "raster_irq_250.s", "main", scene=EXAMPLES_DIR / "raster_irq_250.toml", trace=True)
    html = shown._repr_html_()
    assert "LDA $D01E" in html and "&lt;" not in html.split("</pre>")[1]
