"""Every text of a figure inside the figure: called on each figure physbench draws, just before it
is saved.

A layout engine (constrained or tight) makes room for axis labels and tick labels, and for a
legend's height below the axes, but not for a title or a legend wider than the figure: matplotlib
then cuts them at the edge of the image ("paper Hyperop", "mean over 4 seeds, ban").
:func:`legend_below` makes a figure legend in as many columns as fit; :func:`fit_text` wraps a
title too wide, gives the axes more height when the layout leaves them none, and makes the figure
as much larger as whatever still sticks out. Measured on the figure's own renderer, so it holds
for any font, label or number of entries.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Room (pixels) kept between a text and the figure's edge.
PAD = 3.0
#: Rounds of fitting: each either narrows/wraps something or grows the figure, then redraws.
ROUNDS = 8


def fit_text(fig: Figure) -> Figure:
    """Fit every text of ``fig`` inside it (see the module); returns ``fig``."""
    for _ in range(ROUNDS):
        if _squeezed(fig):  # the layout engine found no room left for the axes: more height
            width, height = fig.get_size_inches()
            fig.set_size_inches(width, height * 1.25)
            continue
        renderer = fig.canvas.get_renderer()
        if _wrap_titles(fig, renderer, fig.bbox.width - 2 * PAD):
            continue
        if not _grow(fig, renderer):
            break
    return fig


def _squeezed(fig: Figure) -> bool:
    """Lay ``fig`` out (its extents are final then); whether the constrained layout gave up
    because the texts and legends left the axes no room (it says so in a warning, kept here)."""
    import warnings

    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        fig.draw_without_rendering()
    squeezed = [w for w in said if "constrained_layout not applied" in str(w.message)]
    for w in said:
        if w not in squeezed:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return bool(squeezed)


def legend_below(
    fig: Figure, handles: Sequence[Any], labels: Sequence[str], *, ncols: int, **kwargs: Any
) -> Any:
    """A figure legend under the axes (``loc="outside lower center"``, which needs a constrained
    layout) in at most ``ncols`` columns, as many fewer as the figure's width needs (a legend's
    columns are fixed when it is made, so it is made again); ``kwargs`` go to ``fig.legend``."""
    n = max(1, min(ncols, len(labels)))
    while True:
        legend = fig.legend(handles, labels, loc="outside lower center", ncols=n, **kwargs)
        if n == 1:
            return legend
        fig.draw_without_rendering()
        width = legend.get_window_extent(fig.canvas.get_renderer()).width
        room = fig.bbox.width - 2 * PAD
        if width <= room:
            return legend
        legend.remove()
        n = max(1, min(n - 1, int(n * room / width)))


def _titles(fig: Figure) -> list[Any]:
    """The figure's title and its axes' titles (left, centre, right)."""
    out = [t for t in (getattr(fig, "_suptitle", None),) if t is not None]
    for ax in fig.axes:
        out += [ax.title, getattr(ax, "_left_title", None), getattr(ax, "_right_title", None)]
    return [t for t in out if t is not None and t.get_visible() and t.get_text()]


def _wrap_titles(fig: Figure, renderer: Any, room: float) -> bool:
    """Wrap each title wider than ``room`` at the characters that fit; whether any changed."""
    changed = False
    for text in _titles(fig):
        width = text.get_window_extent(renderer).width
        lines = text.get_text().split("\n")
        longest = max(len(line) for line in lines)
        if width <= room or longest < 12:
            continue
        chars = max(10, int(longest * room / width * 0.95))
        wrapped = "\n".join(
            textwrap.fill(line, chars) if len(line) > chars else line for line in lines
        )
        if wrapped != text.get_text():
            text.set_text(wrapped)
            changed = True
    return changed


def _grow(fig: Figure, renderer: Any) -> bool:
    """Make ``fig`` as much larger as its drawn content sticks out of it; whether it grew."""
    tight = fig.get_tightbbox(renderer)  # inches, everything drawn (texts, legends, axes)
    width, height = fig.get_size_inches()
    pad = PAD / fig.dpi
    more_w = max(0.0, -tight.x0 + pad) + max(0.0, tight.x1 - width + pad)
    more_h = max(0.0, -tight.y0 + pad) + max(0.0, tight.y1 - height + pad)
    if more_w < 1e-3 and more_h < 1e-3:
        return False
    fig.set_size_inches(width + more_w, height + more_h)
    return True
