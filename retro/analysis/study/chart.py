"""Speed against accuracy as pictures: the overall chart and the per-pair grid (matplotlib, PNG bytes).

x: 6502 cycles per test (mean, log scale, bar from min to max); y: accuracy. Methods on the Pareto
front are drawn in colour and joined by a step line; dominated methods are grey. A method without a
6502 routine (SAT) has no x position: it is drawn as a dashed horizontal line at its accuracy.
"""

from __future__ import annotations

import io
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402

from retro.analysis.study.layout import finish, fit_text, legend_below, place_label, renderer_of  # noqa: E402
from retro.analysis.study.report import ALL, FigureRow  # noqa: E402

GREY = "#b0b0b0"
Styles = dict[str, tuple[str, str]]  # method key -> (colour, marker), from the method objects


def styles_of(methods) -> Styles:
    return {m.key: (m.colour, m.marker) for m in methods}


def _colour(styles: Styles, key: str) -> str:
    return styles.get(key, ("black", "o"))[0]


def _marker(styles: Styles, key: str) -> str:
    return styles.get(key, ("black", "o"))[1]


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    return buffer.getvalue()


def _x_limits(rows: list[FigureRow]) -> tuple[float, float]:
    lows = [r.cycles_min for r in rows if r.cycles_min]
    highs = [r.cycles_max for r in rows if r.cycles_max]
    if not lows:
        return 1, 1000
    return min(lows) / 1.5, max(highs) * 1.5


def _draw_panel(ax, rows: list[FigureRow], styles: Styles, xlim: tuple[float, float], labels: bool,
                title: str, ylim: tuple[float, float] | None = None) -> None:
    """Points, bars, the software front and the host-only lines; the point labels come after the layout
    (`_place_labels`), when the axes' size is final."""
    measured = [r for r in rows if not math.isnan(r.cycles_mean)]
    for r in measured:
        _draw_point(ax, r, styles, labels)
    front = sorted((r for r in measured if r.pareto_software), key=lambda r: r.cycles_mean)
    if len(front) > 1:
        xs = [r.cycles_mean for r in front] + [xlim[1]]
        ys = [r.accuracy for r in front] + [front[-1].accuracy]
        ax.step(xs, ys, where="post", color="black", linewidth=0.8, alpha=0.5, zorder=1)
    for r in rows:
        if math.isnan(r.cycles_mean) and not math.isnan(r.accuracy):
            ax.axhline(r.accuracy, color=_colour(styles, r.method), linestyle="--", linewidth=1.2)
    _style_axes(ax, rows, xlim, ylim, labels, title)


def _draw_point(ax, r: FigureRow, styles: Styles, labels: bool) -> None:
    """A method's mean cycles and accuracy, its cycle range as a bar; lit when on the software front
    or hardware (an open marker), grey otherwise."""
    hardware = r.hardware
    lit = r.pareto_software or hardware
    colour = _colour(styles, r.method) if lit else GREY
    ax.errorbar([r.cycles_mean], [r.accuracy],
                xerr=[[r.cycles_mean - r.cycles_min], [r.cycles_max - r.cycles_mean]],
                fmt=_marker(styles, r.method), color=colour, ecolor=colour, elinewidth=1.2, capsize=3,
                markersize=9 if labels else 6, markeredgecolor="black" if lit else GREY,
                markerfacecolor="none" if hardware else colour, markeredgewidth=1.6 if hardware else 1.0,
                zorder=3 if lit else 2)


def _style_axes(ax, rows: list[FigureRow], xlim: tuple[float, float], ylim: tuple[float, float] | None, labels: bool,
                title: str) -> None:
    ax.set_xscale("log")
    ax.set_xlim(*xlim)
    ax.set_ylim(*(ylim or y_limits(rows)))
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0) if labels else (1.0,)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{100 * v:.0f}%"))
    ax.grid(True, which="major", alpha=0.3)
    ax.set_title(title, fontsize=11 if labels else 8.5)
    ax.tick_params(labelsize=9 if labels else 7)


def y_limits(rows: list[FigureRow]) -> tuple[float, float]:
    """Accuracy from just under the lowest figure to just over 100%."""
    accuracies = [r.accuracy for r in rows if not math.isnan(r.accuracy)]
    y_low = max(0.0, min(accuracies) - 0.06) if accuracies else 0.0
    return y_low, 1.0 + (1.0 - y_low) * 0.06


def _host_line_labels(ax, rows: list[FigureRow], styles: Styles, labels: bool, renderer) -> None:
    """Each host-only method's name on its line, at the right; shortened, then smaller, to stay inside
    the axes."""
    area = ax.get_window_extent(renderer)
    xlim = ax.get_xlim()
    for r in rows:
        if not (math.isnan(r.cycles_mean) and not math.isnan(r.accuracy)):
            continue
        texts = ([f"{r.label}: {100 * r.accuracy:.1f}% (host only, no 6502 routine)", f"{r.label} (host only)"]
                 if labels else [f"{r.method} (host)"])
        for i, text in enumerate(texts):
            t = ax.text(xlim[1] / 1.08, r.accuracy, text, fontsize=8.5 if labels else 6.5,
                        color=_colour(styles, r.method), va="top", ha="right")
            if i == len(texts) - 1:
                fit_text(t, area.width * 0.9, renderer)
            if t.get_window_extent(renderer).x0 >= area.x0 or i == len(texts) - 1:
                break
            t.remove()


# Label positions tried in turn (offset in points, horizontal alignment) until one overlaps nothing.
_LABEL_SLOTS = ((9, -16, "left"), (9, 5, "left"), (-9, 5, "right"), (-9, -16, "right"), (9, -30, "left"),
                (9, 18, "left"), (-9, -30, "right"), (-9, 18, "right"), (9, -44, "left"), (9, 32, "left"),
                (-9, -44, "right"), (-9, 32, "right"), (9, -58, "left"), (-9, -58, "right"))


def _place_labels(ax, rows: list[FigureRow], renderer) -> None:
    """Label each point with its name and figures where the label overlaps no other label, marker or
    line label and stays inside the axes; a point with no such place keeps only its marker (the
    legend names it)."""
    from matplotlib.transforms import Bbox

    taken = [t.get_window_extent(renderer) for t in ax.texts]  # the host-only methods' line labels
    for r in rows:  # keep labels off every marker
        px, py = ax.transData.transform((r.cycles_mean, r.accuracy))
        taken.append(Bbox.from_extents(px - 8, py - 8, px + 8, py + 8))
    for r in sorted(rows, key=lambda r: (-r.pareto_software, r.cycles_mean)):
        text = f"{r.label}\n{r.cycles_mean:.0f} cycles, {100 * r.accuracy:.1f}%"
        if r.hardware:
            text += "\n(hardware: not which pair, not when)"
        lit = r.pareto_software or r.hardware
        place_label(ax, text, (r.cycles_mean, r.accuracy), _LABEL_SLOTS, taken, renderer, fontsize=8.5,
                    color="black" if lit else "#707070",
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8), zorder=4)


def overall_chart(rows: list[FigureRow], styles: Styles, note: str = "") -> bytes:
    return _png(overall_figure(rows, styles, note))


OVERALL_SIZE = (10, 6.5)


def overall_figure(rows: list[FigureRow], styles: Styles, note: str = "", size: tuple[float, float] = OVERALL_SIZE):
    """One large panel for the pooled corpus, every point labelled where a label fits. The front is
    that of the software methods; the hardware latch (hollow marker) is drawn in colour beside it for
    reference. The legend and the note sit below the panel, as wide as the figure allows."""
    chosen = [r for r in rows if r.scope == ALL]
    fig, ax = plt.subplots(figsize=size)
    _draw_panel(ax, chosen, styles, _x_limits(chosen), labels=True,
                title=f"Speed against accuracy, all pairs pooled ({chosen[0].cases if chosen else 0} cases)")
    ax.set_xlabel("6502 cycles per test (mean; bar = min to max over the corpus inputs), log scale")
    ax.set_ylabel("accuracy (share of cases decided correctly)")
    bottom = legend_below(fig, _legend_handles(styles, list(dict.fromkeys(r.method for r in chosen))), 8.5, note=note)
    finish(fig, [ax], bottom)
    renderer = renderer_of(fig)
    _host_line_labels(ax, chosen, styles, True, renderer)
    _place_labels(ax, [r for r in chosen if not math.isnan(r.cycles_mean)], renderer)
    return fig


LEGEND_COLUMNS = 6  # at most this many entries in a row below a grid


def _legend_handles(styles: Styles, keys: list[str]) -> list:
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], marker=_marker(styles, k), color=_colour(styles, k), linestyle="", markersize=8,
                      markeredgecolor="black", label=k) for k in keys]
    handles.append(Line2D([], [], marker="o", color=GREY, linestyle="", markersize=8, label="dominated (grey)"))
    handles.append(Line2D([], [], color="black", alpha=0.5, label="Pareto front (software methods)"))
    return handles


def pairs_chart(rows: list[FigureRow], styles: Styles, columns: int = 6) -> bytes:
    return _png(pairs_figure(rows, styles, columns))


def _pairs_grid(rows: list[FigureRow], columns: int) -> tuple[list[str], int, int]:
    """(the pairs, panels per line, lines) of the pairs chart."""
    scopes = [s for s in dict.fromkeys(r.scope for r in rows) if s != ALL]
    count = max(1, len(scopes))
    columns = min(columns, count)
    return scopes, columns, math.ceil(count / columns)


def pairs_size(rows: list[FigureRow], columns: int = 6) -> tuple[float, float]:
    """The pairs chart's size in inches when none is given: it grows with the pairs and the legend."""
    _, columns, lines = _pairs_grid(rows, columns)
    legend_rows = math.ceil((len(dict.fromkeys(r.method for r in rows)) + 2) / LEGEND_COLUMNS)
    return max(2.5 * columns + 0.6, 11), 2.2 * lines + 1.0 + 0.3 * legend_rows


def pairs_figure(rows: list[FigureRow], styles: Styles, columns: int = 6, size: tuple[float, float] | None = None):
    """A faceted grid, one small panel per shape pair, sharing the x range and the y range."""
    scopes, columns, lines = _pairs_grid(rows, columns)
    keys = list(dict.fromkeys(r.method for r in rows))
    figsize = size or pairs_size(rows, columns)
    fig, axes = plt.subplots(lines, columns, figsize=figsize, squeeze=False)
    pair_rows = [r for r in rows if r.scope != ALL]
    xlim, ylim = _x_limits(pair_rows), y_limits(pair_rows)
    panels = []
    for i, scope in enumerate(scopes):
        ax = axes[i // columns][i % columns]
        _draw_panel(ax, [r for r in rows if r.scope == scope], styles, xlim, labels=False, title=scope, ylim=ylim)
        panels.append(ax)
    for j in range(len(scopes), lines * columns):
        axes[j // columns][j % columns].axis("off")
    bottom = legend_below(fig, _legend_handles(styles, keys), 9, max_columns=LEGEND_COLUMNS)
    renderer = renderer_of(fig)
    xlabel = fig.text(0.5, bottom, "6502 cycles per test (mean, bar = min-max; log scale)", fontsize=10,
                      ha="center", va="bottom")
    fit_text(xlabel, fig.bbox.width - 12, renderer)
    ylabel = fig.text(0.005, 0.5 + bottom / 2, "accuracy", fontsize=10, rotation=90, ha="left", va="center")
    above = (xlabel.get_window_extent(renderer).y1 + 4) / fig.bbox.height
    beside = (ylabel.get_window_extent(renderer).x1 + 4) / fig.bbox.width
    finish(fig, panels, above, left=beside)
    renderer = renderer_of(fig)
    for scope, ax in zip(scopes, panels):
        _host_line_labels(ax, [r for r in rows if r.scope == scope], styles, False, renderer)
    return fig
