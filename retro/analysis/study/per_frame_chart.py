"""The cost-per-frame chart: 6502 cycles per frame against the number of objects, one panel per broad
phase (sharing the y range), one line per method, the budgets as horizontal lines."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402

from retro.analysis.study.broad_phase import PHASES  # noqa: E402
from retro.analysis.study.chart import _png  # noqa: E402
from retro.analysis.study.layout import finish, legend_below, renderer_of  # noqa: E402
from retro.analysis.study.per_frame import ONCE, PHASE_LABELS, PerFrame  # noqa: E402

SIZE = (13, 6.5)
BUDGET_COLOURS = ("#444444", "#888888")
MARK_EVERY = 8


def per_frame_chart(result: PerFrame, note: str = "") -> bytes:
    return _png(per_frame_figure(result, note))


def _y_limits(result: PerFrame) -> tuple[float, float]:
    values = [r.frame_cycles for r in result.rows if r.frame_cycles > 0]
    low = min(values + [float(result.budget.lines_cycles)])
    high = max(values + [float(result.budget.frame_cycles)])
    return low / 1.6, high * 1.6


def per_frame_figure(result: PerFrame, note: str = "", size: tuple[float, float] = SIZE):
    styles = {m.key: (m.colour, m.marker) for m in result.methods}
    keys = list(dict.fromkeys(r.method for r in result.rows))
    labels = {r.method: r.label for r in result.rows}
    fig, axes = plt.subplots(1, len(PHASES), figsize=size, sharey=True, squeeze=False)
    ylim = _y_limits(result)
    b = result.budget
    frame, lines = float(b.frame_cycles), float(b.lines_cycles)
    budgets = ((frame, f"{b.label} frame: {frame:,.0f}"), (lines, f"{b.lines} raster lines: {lines:,.0f}"))
    counts = sorted({r.objects for r in result.rows})
    for ax, phase in zip(axes[0], PHASES):
        _panel(ax, result, phase, keys, styles)
        for (value, _), colour in zip(budgets, BUDGET_COLOURS):
            ax.axhline(value, color=colour, linestyle="--", linewidth=1.1)
        _axes_style(ax, ylim, counts, phase)
    axes[0][0].set_ylabel("6502 cycles per frame (log scale)")
    handles = [Line2D([], [], color=styles.get(k, ("black", "o"))[0], marker=styles.get(k, ("black", "o"))[1],
                      markeredgecolor="black", label=labels[k]) for k in keys]
    handles += [Line2D([], [], color=c, linestyle="--", label=text) for (_, text), c in zip(budgets, BUDGET_COLOURS)]
    if any(r.phase == ONCE for r in result.rows):
        handles.append(Line2D([], [], color="black", linestyle=":", label="one call a frame (hardware, not which pair)"))
    bottom = legend_below(fig, handles, 8.5, note=note)
    finish(fig, list(axes[0]), bottom)
    _budget_names(fig, list(axes[0]), budgets)
    return fig


def _panel(ax, result: PerFrame, phase: str, keys: list[str], styles: dict) -> None:
    """Each method's curve in one broad phase (and a dotted one for a once-a-frame method)."""
    for key in keys:
        colour, marker = styles.get(key, ("black", "o"))
        for chosen_phase, style in ((phase, "-"), (ONCE, ":")):
            chosen = sorted((r for r in result.rows if r.method == key and r.phase == chosen_phase),
                            key=lambda r: r.objects)
            if chosen:
                ax.plot([r.objects for r in chosen], [r.frame_cycles for r in chosen], color=colour,
                        linestyle=style, marker=marker, markevery=MARK_EVERY, markersize=6,
                        markeredgecolor="black", linewidth=1.6)


def _axes_style(ax, ylim: tuple[float, float], counts: list[int], phase: str) -> None:
    ax.set_yscale("log")
    ax.set_ylim(*ylim)
    ax.set_xlim(0, max(counts) + 1 if counts else 1)
    ax.yaxis.set_major_locator(LogLocator(base=10))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:,.0f}"))
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.grid(True, which="major", alpha=0.3)
    ax.set_title(PHASE_LABELS[phase], fontsize=11)
    ax.set_xlabel("objects tested each frame")


def _budget_names(fig, axes: list, budgets: tuple) -> None:
    """The budgets' names on their lines, where they fit."""
    renderer = renderer_of(fig)
    for ax in axes:
        area = ax.get_window_extent(renderer)
        for value, text in budgets:
            t = ax.text(0.5, value * 1.08, text, fontsize=8, color="#333333", va="bottom", ha="left",
                        bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.8))
            box = t.get_window_extent(renderer)
            if box.x1 > area.x1 or box.y1 > area.y1 or math.isnan(box.x0):
                t.remove()
