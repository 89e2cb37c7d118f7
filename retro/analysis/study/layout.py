"""Figure layout that holds at any figure size: the legend and notes measured and stacked below the
plots, titles shrunk to their width, labels placed only where they overlap nothing.

Every function measures the text as drawn (the Agg renderer) instead of assuming sizes, so a chart
drawn smaller or larger keeps its legend whole, its notes inside the figure and its labels apart.
"""

from __future__ import annotations

import textwrap

MARGIN_PX = 6  # kept free at the figure's edges and between stacked blocks
MIN_FONT = 5.5  # titles shrink down to this size, then they wrap


def renderer_of(fig):
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def fit_text(text, width_px: float, renderer, min_size: float = MIN_FONT) -> None:
    """Shrink a Text artist until it is at most width_px long (along its direction: a label turned
    90 degrees is measured upwards); wrap it once it is at min_size."""
    def length() -> float:
        box = text.get_window_extent(renderer)
        return box.height if text.get_rotation() % 180 == 90 else box.width

    while length() > width_px and text.get_fontsize() > min_size:
        text.set_fontsize(max(min_size, text.get_fontsize() - 0.5))
    if length() > width_px:
        words = text.get_text().replace("\n", " ")
        for columns in range(len(words), 8, -4):
            text.set_text(textwrap.fill(words, columns))
            if length() <= width_px:
                break


def wrap_note(fig, note: str, fontsize: float, renderer) -> object:
    """A note across the bottom of the figure, wrapped to its width."""
    width = fig.bbox.width - 2 * MARGIN_PX
    text = fig.text(MARGIN_PX / fig.bbox.width, MARGIN_PX / fig.bbox.height, note, fontsize=fontsize,
                    color="#555555", va="bottom", ha="left")
    if text.get_window_extent(renderer).width > width:
        for columns in range(len(note), 8, -2):
            text.set_text(textwrap.fill(note, columns))
            if text.get_window_extent(renderer).width <= width:
                break
    return text


def legend_below(fig, handles, fontsize: float, note: str = "", note_size: float = 8.0,
                 max_columns: int | None = None) -> float:
    """A legend (and an optional note under it) across the bottom of the figure, with as many columns
    as fit its width. Returns the share of the figure's height they take (plots go above)."""
    renderer = renderer_of(fig)
    bottom_px = MARGIN_PX
    if note:
        text = wrap_note(fig, note, note_size, renderer)
        bottom_px = text.get_window_extent(renderer).y1 + MARGIN_PX
    width = fig.bbox.width - 2 * MARGIN_PX
    columns = min(len(handles), max_columns or len(handles))
    while True:
        legend = fig.legend(handles=handles, loc="lower center", ncol=columns, fontsize=fontsize, frameon=False,
                            bbox_to_anchor=(0.5, bottom_px / fig.bbox.height), borderaxespad=0.0)
        box = legend.get_window_extent(renderer)
        if box.width <= width or columns == 1:
            break
        legend.remove()
        columns -= 1
    return (box.y1 + MARGIN_PX) / fig.bbox.height


def finish(fig, axes, bottom: float, left: float = 0.0, top: float = 1.0) -> None:
    """Lay the panels out in (left, bottom)-(1, top) of the figure, then fit every title and axis label
    to its panel (twice: fitting frees room that the next layout gives to the panels)."""
    for _ in range(2):
        fig.tight_layout(rect=(left, bottom, 1, top))
        renderer = renderer_of(fig)
        for ax in axes:
            area = ax.get_window_extent(renderer)
            fit_text(ax.title, area.width, renderer)
            fit_text(ax.xaxis.label, area.width, renderer)
            fit_text(ax.yaxis.label, area.height, renderer)
    fig.tight_layout(rect=(left, bottom, 1, top))


def title_above(fig, text: str, fontsize: float) -> float:
    """A figure title across the top, fitted to the width; returns the share of the height below it."""
    renderer = renderer_of(fig)
    title = fig.text(0.5, 1 - MARGIN_PX / fig.bbox.height, text, fontsize=fontsize, ha="center", va="top")
    fit_text(title, fig.bbox.width - 2 * MARGIN_PX, renderer)
    return (title.get_window_extent(renderer).y0 - MARGIN_PX) / fig.bbox.height


def place_label(ax, text: str, xy, slots, taken: list, renderer, **style):
    """Annotate xy with text at the first slot (dx, dy points, alignment) whose box stays inside the
    axes and overlaps no box in `taken`; None (and nothing drawn) when no slot fits."""
    area = ax.get_window_extent(renderer)
    for dx, dy, align in slots:
        note = ax.annotate(text, xy, textcoords="offset points", xytext=(dx, dy), ha=align, **style)
        box = note.get_window_extent(renderer)
        inside = area.x0 <= box.x0 and box.x1 <= area.x1 and area.y0 <= box.y0 and box.y1 <= area.y1
        if inside and not any(box.overlaps(other) for other in taken):
            taken.append(box)
            return note
        note.remove()
    return None
