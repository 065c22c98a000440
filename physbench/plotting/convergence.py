"""Convergence plot like the paper's Fig. 3: best-so-far errors per iteration.

Best-so-far is chosen by image MSE (the truth is not peeked at), so the normalized-MSE curve shows
the normalized MSE of the iterate best by image MSE; it need not fall monotonically, the image-MSE
curve does. Iterations are numbered as in ``physbench run``'s table (0: the initial guess).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.plotting.units import DIMENSIONLESS, IMAGE_MSE_UNIT

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from physbench.loop import History

#: (field, y label, panel title) of each panel, top to bottom
PANELS = (
    (
        "best_nmse",
        f"normalized MSE ({DIMENSIONLESS})",
        "normalized MSE of the best-so-far iterate by image MSE",
    ),
    (
        "best_loss",
        f"image MSE ({IMAGE_MSE_UNIT})",
        "best-so-far image MSE (frames' pixel values in [0, 1])",
    ),
)
XLABEL = "iteration (as numbered in the table; 0: initial guess)"


def _curves(runs: Sequence[History], field: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(iteration numbers, values (runs, n)), cut to the shortest run; None without the field."""
    vals = [[getattr(r, field) for r in h.iterations] for h in runs]
    if any(v is None for row in vals for v in row):
        return None
    n = min(len(row) for row in vals)
    x = np.array([r.iteration for r in runs[0].iterations[:n]])
    return x, np.array([row[:n] for row in vals], dtype=float)


def _groups(
    histories: History | Sequence[History] | Mapping[str, Sequence[History]],
) -> Mapping[str, Sequence[History]]:
    from physbench.loop import History

    if isinstance(histories, History):
        return {histories.estimator: [histories]}
    if isinstance(histories, Mapping):
        return histories
    groups: dict[str, list[History]] = {}
    for h in histories:
        groups.setdefault(h.estimator, []).append(h)
    return groups


def run_title(history: History) -> str:
    """The title of one ``physbench run``: scene and unknowns, then estimator, seed, engine(s),
    renderer and resolution, and the observation's blur and noise (pixels)."""
    meta: Mapping[str, Any] = history.meta
    engine = str(meta.get("simulator", "?"))
    observer = meta.get("observe_engine")
    engines = f"engine {engine}" + (
        f", observed with {observer}" if observer and observer != engine else ""
    )
    seeing = f"{meta.get('renderer', '?')} {meta.get('resolution', '?')} px"
    blur, noise = meta.get("blur") or 0.0, meta.get("noise") or 0.0
    return (
        f"{meta.get('scene', '?')}: {', '.join(history.keys)}\n"
        f"{history.estimator}, seed {history.seed}, {engines}, {seeing}, "
        f"blur {blur:g} px, noise {noise:g}"
    )


def convergence_figure(
    histories: History | Sequence[History] | Mapping[str, Sequence[History]],
    *,
    title: str | None = None,
) -> Figure:
    """The figure of best-so-far errors against the iteration number: the normalized MSE of the
    best-by-image iterate (top, when every run knows its truth) and the image MSE (bottom); one
    line per label: the median over its runs, with the interquartile range shaded (on a log axis
    a mean ± std band runs below zero). The legend sits outside the axes, under the x label."""
    groups = _groups(histories)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = list(PANELS)
    if any(_curves(runs, "best_nmse") is None for runs in groups.values()):
        panels = panels[1:]
    fig, axes = plt.subplots(
        len(panels),
        1,
        figsize=(6, 2.6 * len(panels) + 0.6),
        sharex=True,
        squeeze=False,
        layout="constrained",
    )
    for ax, (field, ylabel, what) in zip(axes[:, 0], panels, strict=True):
        for label, runs in groups.items():
            curves = _curves(runs, field)
            if curves is None:
                continue
            x, y = curves
            lo, mid, hi = np.percentile(y, [25, 50, 75], axis=0)
            what_line = "median, IQR" if len(runs) > 1 else "one run"
            (line,) = ax.plot(
                x,
                mid,
                marker="o",
                ms=3,
                label=f"{label} ({what_line}, n={len(runs)})" if len(runs) > 1 else label,
            )
            if len(runs) > 1:
                ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.2)
        ax.set_yscale("log")
        ax.set_ylabel(ylabel, fontsize="small")
        ax.set_title(what, fontsize="small")
        ax.grid(True, which="both", alpha=0.3)
    axes[-1, 0].set_xlabel(XLABEL)
    axes[-1, 0].xaxis.get_major_locator().set_params(integer=True)
    if title:
        fig.suptitle(title, fontsize="medium")
    from physbench.plotting.layout import fit_text, legend_below

    handles, labels = axes[0, 0].get_legend_handles_labels()
    legend_below(fig, handles, labels, ncols=4, fontsize="small")
    return fit_text(fig)


def plot_convergence(
    histories: History | Sequence[History] | Mapping[str, Sequence[History]],
    path: str | Path,
    *,
    title: str | None = None,
) -> Path:
    """Write :func:`convergence_figure` to ``path`` (the suffix picks the format); returns the
    path."""
    import matplotlib.pyplot as plt

    fig = convergence_figure(histories, title=title)
    out = Path(path)
    try:
        fig.savefig(out, dpi=120)
    finally:
        plt.close(fig)
    return out
