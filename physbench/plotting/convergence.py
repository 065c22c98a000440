"""Convergence plot like the paper's Fig. 3: best-so-far errors per iteration.

Best-so-far is chosen by image MSE (the truth is not peeked at), so the normalized-MSE curve
need not fall monotonically; the image-MSE curve does.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from physbench.loop import History


def _curves(runs: Sequence[History], field: str) -> np.ndarray | None:
    vals = [[getattr(r, field) for r in h.iterations] for h in runs]
    if any(v is None for row in vals for v in row):
        return None
    n = min(len(row) for row in vals)
    return np.array([row[:n] for row in vals], dtype=float)


def plot_convergence(
    histories: History | Sequence[History] | Mapping[str, Sequence[History]],
    path: str | Path,
    *,
    title: str | None = None,
) -> Path:
    """Write a figure of best-so-far normalized MSE (top, when the truth is known) and image MSE
    (bottom) against the iteration count; one line per label: the median over its runs, with the
    interquartile range shaded (on a log axis a mean ± std band runs below zero). Returns the
    path."""
    from physbench.loop import History

    if isinstance(histories, History):
        groups: Mapping[str, Sequence[History]] = {histories.estimator: [histories]}
    elif isinstance(histories, Mapping):
        groups = histories
    else:
        groups = {}
        for h in histories:
            groups.setdefault(h.estimator, []).append(h)  # type: ignore[attr-defined]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("best_nmse", "best-so-far normalized MSE"), ("best_loss", "best-so-far image MSE")]
    if any(_curves(runs, "best_nmse") is None for runs in groups.values()):
        panels = panels[1:]
    fig, axes = plt.subplots(
        len(panels), 1, figsize=(6, 2.6 * len(panels) + 0.6), sharex=True, squeeze=False
    )
    for ax, (field, ylabel) in zip(axes[:, 0], panels, strict=True):
        for label, runs in groups.items():
            y = _curves(runs, field)
            if y is None:
                continue
            x = np.arange(1, y.shape[1] + 1)
            lo, mid, hi = np.percentile(y, [25, 50, 75], axis=0)
            what = "median, IQR" if len(runs) > 1 else "one run"
            (line,) = ax.plot(
                x,
                mid,
                marker="o",
                ms=3,
                label=f"{label} ({what}, n={len(runs)})" if len(runs) > 1 else label,
            )
            if len(runs) > 1:
                ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.2)
        ax.set_yscale("log")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
    axes[-1, 0].set_xlabel("iterations (simulations)")
    axes[-1, 0].xaxis.get_major_locator().set_params(integer=True)
    axes[0, 0].legend(fontsize="small")
    if title:
        axes[0, 0].set_title(title)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
