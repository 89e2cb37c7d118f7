"""Readability of a matplotlib figure, checked from what the renderer draws (not from the layout code):
every visible text (titles, axis and tick labels, point labels, legend entries, notes) lies inside the
figure and overlaps no other text, and every legend lies wholly inside the figure."""

from __future__ import annotations

import itertools

from matplotlib.text import Text

TOLERANCE = 1.0  # pixels: antialiasing may touch a neighbour's edge


def _hidden_tick_labels(fig) -> set[int]:
    """Tick labels matplotlib keeps for ticks outside the view (it does not draw them)."""
    hidden = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            slack = 1e-9 * max(abs(lo), abs(hi), 1)
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                loc = tick.get_loc()
                if loc is None or not lo - slack <= loc <= hi + slack:
                    hidden.update((id(tick.label1), id(tick.label2)))
    return hidden


def drawn_texts(fig) -> list[tuple[str, object]]:
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    hidden = _hidden_tick_labels(fig)
    out = []
    for text in fig.findobj(Text):
        if not text.get_visible() or not text.get_text().strip() or id(text) in hidden:
            continue
        if text.axes is not None and not text.axes.get_visible():
            continue
        if text.figure is None:
            continue
        out.append((text.get_text(), text.get_window_extent(renderer)))
    return out


def _apart(a, b) -> bool:
    return (a.x1 - TOLERANCE <= b.x0 + TOLERANCE or b.x1 - TOLERANCE <= a.x0 + TOLERANCE
            or a.y1 - TOLERANCE <= b.y0 + TOLERANCE or b.y1 - TOLERANCE <= a.y0 + TOLERANCE)


def _inside(box, frame) -> bool:
    return (box.x0 >= frame.x0 - TOLERANCE and box.y0 >= frame.y0 - TOLERANCE and box.x1 <= frame.x1 + TOLERANCE
            and box.y1 <= frame.y1 + TOLERANCE)


def problems(fig) -> list[str]:
    """Every text outside the figure, every two texts over each other, every legend cut off."""
    texts = drawn_texts(fig)
    frame = fig.bbox
    found = [f"outside the figure: {text[:50]!r}" for text, box in texts if not _inside(box, frame)]
    found += [f"{a[:40]!r} over {b[:40]!r}" for (a, box_a), (b, box_b) in itertools.combinations(texts, 2)
              if not _apart(box_a, box_b)]
    renderer = fig.canvas.get_renderer()
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    found += ["a legend is cut off" for legend in legends if not _inside(legend.get_window_extent(renderer), frame)]
    return found
