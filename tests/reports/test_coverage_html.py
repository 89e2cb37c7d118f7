"""The HTML report of the hand-worked routine (handworked.py), opened in a real headless browser
(Debian's chromium): what a person sees, read from the screenshot's pixels at each line's place, and
the page after its script ran (`--dump-dom`). On CI (CI=true) a missing browser fails these tests
(.ci/run installs it); elsewhere they are skipped, saying so."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from collections import Counter
from pathlib import Path

import pytest
from handworked import DATA, ENTRY, HAND
from PIL import Image

from retro.loaders import load_program
from retro.loaders.source_lines import read_source_map
from retro.reports.annotated import RoutineCode, annotate
from retro.reports.coverage_html import (
    INDEX,
    MISSED_COLOUR,
    PARTIAL_COLOUR,
    RUN_COLOUR,
    WORST_COLOUR,
    html_pages,
)

WINDOW = (1280, 900)
BROWSER_SECONDS = 120


def rgb(colour: str) -> tuple[int, int, int]:
    return tuple(int(colour[i:i + 2], 16) for i in (1, 3, 5))


def chromium() -> str:
    found = shutil.which("chromium") or ("/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)
    if found is None:
        if os.environ.get("CI") == "true":
            pytest.fail("chromium is missing on CI: .ci/run installs it (apt-get install chromium)")
        pytest.skip("no headless browser: apt-get install chromium")
    return found


def browse(page: Path, *how: str, fragment: str = "") -> subprocess.CompletedProcess:
    command = [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
               "--force-device-scale-factor=1", f"--window-size={WINDOW[0]},{WINDOW[1]}", *how,
               page.as_uri() + fragment]
    done = subprocess.run(command, capture_output=True, text=True, timeout=BROWSER_SECONDS)
    assert done.returncode == 0, done.stderr[-2000:]
    return done


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("htmlcov")
    program = load_program(DATA / "sumto.prg", symbols=DATA / "sumto.dbg")
    code = RoutineCode("sumto", program.code, program.origin, ENTRY, symbols=dict(program.symbols),
                       program_file=str(DATA / "sumto.prg"), source_map=read_source_map(DATA / "sumto.dbg"))
    pages = html_pages([annotate(code, HAND)], lambda file: Path(file).read_text().splitlines())
    for name, text in pages.items():
        (folder / name).write_text(text)
    return folder


@pytest.fixture(scope="module")
def seen(report) -> tuple[str, Image.Image]:
    """The routine's page as the browser laid it out (DOM after the script) and drew it."""
    page = report / "sumto.html"
    dom = browse(page, "--dump-dom").stdout
    shot = report / "shot.png"
    browse(page, f"--screenshot={shot}")
    return dom, Image.open(shot).convert("RGB")


def row_box(dom: str, address: int) -> tuple[int, int]:
    tag = re.search(rf'<tr id="a{address:04X}"[^>]*>', dom)
    assert tag, f"no row for ${address:04X}"
    top = re.search(r'data-top="(\d+)"', tag.group(0))
    height = re.search(r'data-height="(\d+)"', tag.group(0))
    assert top and height, "the page's script did not run"
    return int(top.group(1)), int(height.group(1))


def row_colours(image: Image.Image, dom: str, address: int) -> Counter:
    """The colours along the middle of a line, as drawn."""
    top, height = row_box(dom, address)
    y = top + height // 2
    assert 0 < y < image.height, "the line is outside the screenshot"
    return Counter(image.getpixel((x, y)) for x in range(image.width))


@pytest.mark.parametrize("address, colour", [
    (0xC010, MISSED_COLOUR), (0xC012, MISSED_COLOUR),  # never run
    (0xC00A, PARTIAL_COLOUR),  # BCS: never taken
    (0xC000, RUN_COLOUR), (0xC00D, RUN_COLOUR),  # run; BNE went both ways
])
def test_each_line_is_drawn_in_its_coverage_colour(seen, address, colour):
    dom, image = seen
    colours = row_colours(image, dom, address)
    assert colours[rgb(colour)] > image.width // 4, colours.most_common(4)
    for other in {MISSED_COLOUR, PARTIAL_COLOUR, RUN_COLOUR} - {colour}:
        assert colours[rgb(other)] == 0


@pytest.mark.parametrize("address, on_path", [(0xC000, True), (0xC00D, True), (0xC00F, True), (0xC010, False)])
def test_the_worst_case_path_has_its_bar(seen, address, on_path):
    dom, image = seen
    colours = row_colours(image, dom, address)
    assert (colours[rgb(WORST_COLOUR)] > 0) is on_path


def test_hits_are_a_heat_map(seen):
    """The hits cell of a line run 4 times is drawn more orange than one run 3 times."""
    dom, image = seen

    def orange(address: int) -> int:  # the least blue among the line's pixels: the heat cell's background
        return min(b for (r, g, b), n in row_colours(image, dom, address).items() if n > 20 and r > 200)

    assert orange(0xC006) < orange(0xC000) < 200


def test_the_script_filters_to_the_lines_to_look_at(report):
    """`#missed` leaves only the lines that need a look: the browser hides run lines."""
    dom = browse(report / "sumto.html", "--dump-dom", fragment="#missed").stdout
    assert re.search(r'<body[^>]*class="[^"]*missed-only', dom)
    assert 'data-ready="yes"' in dom
    for address in (0xC000, 0xC00D):  # run lines: not drawn
        assert row_box(dom, address)[1] == 0
    for address in (0xC00A, 0xC010, 0xC012):
        assert row_box(dom, address)[1] > 0


def test_the_index_links_each_routine_with_its_figures(report):
    dom = browse(report / INDEX, "--dump-dom").stdout
    assert '<a href="sumto.html">sumto</a>' in dom
    assert re.search(r"<td>9 / 11</td><td>81\.8%</td><td>5 / 6</td><td>83\.3%</td><td>51</td>", dom)


def test_pages_stand_alone(report):
    """No file or address outside the page: inline CSS and script only."""
    for page in report.glob("*.html"):
        text = page.read_text()
        assert not re.search(r'(src|href)="(?!#|sumto\.html|index\.html)', text), page.name
        assert "http" not in text
