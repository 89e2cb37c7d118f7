"""Pictures of the stability study (matplotlib, PNG bytes)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import math  # noqa: E402

from retro.analysis.study.chart import _png  # noqa: E402
from retro.analysis.study.layout import finish, legend_below, title_above  # noqa: E402
from retro.analysis.study.stability.tunnelling import GROUP, SWEPT, TunnelRow  # noqa: E402

SWEPT_LABEL = "swept tight box (retro.geometry)"
LEGEND_COLUMNS = 2


def group_label(key: str, methods) -> str:
    """The label of a tunnelling line: its methods' labels (or the swept reference's)."""
    if key == SWEPT:
        return SWEPT_LABEL
    labels = {m.key: m.label for m in methods}
    first, *others = key.split(GROUP)
    return labels.get(first, first) + (f" (and {', '.join(others)})" if others else "")


def tunnelling_chart(rows: list[TunnelRow], mover: str, methods) -> bytes:
    return _png(tunnelling_figure(rows, mover, methods))


def tunnelling_figure(rows: list[TunnelRow], mover: str, methods, size: tuple[float, float] | None = None):
    """One panel per wall thickness: miss rate against speed, one line per method group."""
    by_key = {m.key: m for m in methods}
    thicknesses = sorted({r.thickness for r in rows})
    groups = list(dict.fromkeys(r.method for r in rows))
    legend_rows = math.ceil(len(groups) / LEGEND_COLUMNS)
    height = 3.6 + 0.25 * legend_rows
    fig, axes = plt.subplots(1, len(thicknesses), figsize=size or (3.6 * len(thicknesses) + 1.5, height), sharey=True,
                             squeeze=False)
    for ax, t in zip(axes[0], thicknesses):
        for key in groups:
            first = by_key.get(key.split(GROUP)[0])
            chosen = sorted((r for r in rows if r.method == key and r.thickness == t), key=lambda r: r.speed)
            ax.plot([r.speed for r in chosen], [100 * r.miss_rate for r in chosen],
                    color="black" if first is None else first.colour,
                    linestyle="--" if key == SWEPT else "-", marker=None if first is None else first.marker,
                    markevery=4, markersize=5, linewidth=2.4 if key == SWEPT else 1.5, label=group_label(key, methods))
        ax.set_title(f"obstacle {t} px thick", fontsize=10)
        ax.set_xlabel("speed (pixels per frame)")
        ax.grid(True, alpha=0.3)
        ax.set_ylim(-3, 100)
    axes[0][0].set_ylabel("crossings missed (% of start phases)")
    handles, _ = axes[0][0].get_legend_handles_labels()
    bottom = legend_below(fig, handles, 8.5, max_columns=LEGEND_COLUMNS)
    top = title_above(fig, f"Tunnelling: a {mover} crossing a wall at v px/frame, tested once per frame", 11)
    finish(fig, list(axes[0]), bottom, top=top)
    return fig


def wrap_chart(maps: dict, rows: list) -> bytes:
    return _png(wrap_figure(maps, rows))


def wrap_figure(maps: dict, rows: list, size: tuple[float, float] | None = None):
    """One map per (video, software test): for every pair of X registers, whether the software box
    test and the VIC-II agree."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from retro.analysis.study.stability.wrap import X_RANGE

    colours = ["#ffffff", "#c8c8c8", "#ff7f0e", "#1f77b4"]
    names = ["both: no collision", "both: collision", "software only (chip shows none)",
             "chip only (software misses)"]
    keys = list(maps)
    fig, axes = plt.subplots(1, len(keys), figsize=size or (3.9 * len(keys), 4.9), squeeze=False)
    counts = {(r.video, r.test): r for r in rows}
    for ax, key in zip(axes[0], keys):
        ax.imshow(maps[key], cmap=ListedColormap(colours), vmin=0, vmax=3, origin="lower",
                  interpolation="nearest", extent=(0, X_RANGE, 0, X_RANGE))
        r = counts[key]
        ax.set_title(f"{key[0].upper()}: {key[1]}\nsoftware only {r.software_only}, chip only {r.hardware_only}",
                     fontsize=8.5)
        ax.set_xlabel("X of sprite b", fontsize=8.5)
        ax.set_xticks([0, 128, 256, 384, 504])
        ax.set_yticks([0, 128, 256, 384, 504])
        ax.tick_params(labelsize=7.5)
    axes[0][0].set_ylabel("X of sprite a", fontsize=8.5)
    bottom = legend_below(fig, [Patch(color=c, label=n, ec="black", lw=0.5) for c, n in zip(colours, names)], 8.5)
    top = title_above(fig, "Coordinate wrap: box test on sprite X registers against the VIC-II (two full 24x21 "
                           "sprites)", 10.5)
    finish(fig, list(axes[0]), bottom, top=top)
    return fig
