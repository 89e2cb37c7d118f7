"""Every chart of the study readable at every size: drawn at 0.6, 1 and 1.6 times its size, no text lies
over another or outside the figure and no legend is cut off (tests/study/figure_checks.py checks the
rendered boxes); the per-pair panels share one y range."""

from __future__ import annotations

import matplotlib.pyplot as plt
import pytest
from figure_checks import problems

from retro.analysis.study.methods import BUILTIN
from retro.paths import PROJECT_ROOT

SCALES = (0.6, 1.0, 1.6)
STUDY = PROJECT_ROOT / "docs" / "images" / "study"


def _scaled(size, scale):
    return (size[0] * scale, size[1] * scale)


@pytest.fixture(scope="module")
def rows():
    """The full corpus's figures (36 pairs, ten methods): the most crowded chart the project draws."""
    from retro.analysis.study.report import rows_from_csv

    return rows_from_csv((STUDY / "study.csv").read_text())


NOTE = ("corpus: ball, ring, ship, bullet, bar, pentagon, lshape, mc_gem and 40 sprites of yours with long names "
        "(36 pairs, 69372 cases); cycles measured in py65 on every case (at most: latch 192 per pair)")


@pytest.mark.parametrize("scale", SCALES)
def test_overall_chart(rows, scale):
    from retro.analysis.study.chart import OVERALL_SIZE, overall_figure, styles_of

    fig = overall_figure(rows, styles_of(BUILTIN), NOTE, size=_scaled(OVERALL_SIZE, scale))
    assert problems(fig) == []
    plt.close(fig)


@pytest.mark.parametrize("scale", SCALES)
def test_pairs_chart(rows, scale):
    from retro.analysis.study.chart import pairs_figure, pairs_size, styles_of

    fig = pairs_figure(rows, styles_of(BUILTIN), size=_scaled(pairs_size(rows), scale))
    assert problems(fig) == []
    panels = [ax for ax in fig.axes if ax.get_title()]
    assert len(panels) == 36
    assert len({ax.get_ylim() for ax in panels}) == 1  # one accuracy range for every pair
    assert len({ax.get_xlim() for ax in panels}) == 1
    lowest = min(r.accuracy for r in rows if r.scope != "ALL")
    assert panels[0].get_ylim()[0] <= lowest
    plt.close(fig)


@pytest.mark.parametrize("scale", SCALES)
def test_per_frame_chart(scale):
    from retro.analysis.study.per_frame import PAL_BUDGET, BroadTable, PerFrame
    from retro.analysis.study.per_frame_chart import SIZE, per_frame_figure
    from retro.analysis.study.per_frame_report import rows_from_csv

    frame_rows = rows_from_csv((STUDY / "per_frame.csv").read_text())
    result = PerFrame(frame_rows, PAL_BUDGET, {}, BroadTable({}, {}, 0, 0), (), BUILTIN)
    fig = per_frame_figure(result, NOTE, size=_scaled(SIZE, scale))
    assert problems(fig) == []
    plt.close(fig)


@pytest.fixture(scope="module")
def tunnel():
    from retro.analysis.study.corpus import load_shapes
    from retro.analysis.study.stability import tunnelling

    (bullet,) = load_shapes(["bullet"])
    return tunnelling.tunnelling_table(bullet)


@pytest.mark.parametrize("scale", SCALES)
def test_tunnelling_chart(tunnel, scale):
    from retro.analysis.study.stability import charts

    default = charts.tunnelling_figure(tunnel, "bullet", BUILTIN)
    size = tuple(default.get_size_inches())
    plt.close(default)
    fig = charts.tunnelling_figure(tunnel, "bullet", BUILTIN, size=_scaled(size, scale))
    assert problems(fig) == []
    plt.close(fig)


@pytest.mark.parametrize("scale", SCALES)
def test_wrap_chart(scale):
    from retro.analysis.study.stability import charts, wrap

    table, maps = wrap.wrap_table()
    fig = charts.wrap_figure(maps, table, size=_scaled((3.9 * len(maps), 4.9), scale))
    assert problems(fig) == []
    plt.close(fig)


def test_the_checker_sees_an_overlap_and_a_cut_legend():
    """The check itself: two labels at one place, and a legend hanging off the figure, are reported."""
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.text(0.5, 0.5, "one label")
    ax.text(0.5, 0.5, "another label")
    ax.plot([0, 1], [0, 1], label="a line with a long legend entry")
    fig.legend(loc="center", bbox_to_anchor=(1.0, 0.5))
    found = problems(fig)
    assert any("over" in p for p in found) and "a legend is cut off" in found
    plt.close(fig)
