"""The marginals of a run's posterior: one histogram per unknown over its prior range, with the
median, the 50 % and 90 % intervals and the truth when it is known. ``physbench run --plot``
writes it beside the convergence plot for an estimator that returns a posterior."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from physbench.posterior.samples import Posterior


def posterior_path(plot: str | Path) -> Path:
    """Where the marginals go for a convergence plot at ``plot``: ``run.png`` ->
    ``run.posterior.png``."""
    p = Path(plot)
    return p.with_name(f"{p.stem}.posterior{p.suffix}")


def posterior_figure(
    posterior: Posterior, truth: Mapping[str, float] | None = None, *, title: str | None = None
) -> Figure:
    """One panel per unknown: the samples' histogram, the 90 % interval shaded light, the 50 %
    darker, the median as a line and the truth (when known) as a dashed black line. The x axis
    spans the prior range, so a posterior as wide as the prior is visibly so."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = posterior.keys
    fig, axes = plt.subplots(
        1, len(keys), figsize=(3.4 * len(keys), 2.8), squeeze=False, layout="constrained"
    )
    med, i50, i90 = posterior.median(), posterior.interval(0.5), posterior.interval(0.9)
    undetermined = set(posterior.undetermined())
    for j, (ax, k) in enumerate(zip(axes[0], keys, strict=True)):
        lo, hi = posterior.low[j], posterior.high[j]
        ax.hist(posterior.samples[:, j], bins=40, color="tab:blue", alpha=0.6)
        ax.axvspan(*i90[k], color="tab:orange", alpha=0.15, label="90 % interval")
        ax.axvspan(*i50[k], color="tab:orange", alpha=0.3, label="50 % interval")
        ax.axvline(med[k], color="tab:orange", lw=1.5, label="median")
        if truth is not None and k in truth:
            ax.axvline(truth[k], color="black", ls="--", lw=1.2, label="truth")
        ax.set_xlim(lo, hi)
        ax.set_yticks([])
        ax.set_xlabel(k + (" (not determined)" if k in undetermined else ""), fontsize="small")
    state = "" if posterior.complete else " (incomplete)"
    fig.suptitle(
        title or f"posterior ({posterior.method}{state}, {len(posterior)} samples)",
        fontsize="medium",
    )
    from physbench.plotting.layout import fit_text, legend_below

    handles, labels = axes[0, 0].get_legend_handles_labels()
    legend_below(fig, handles, labels, ncols=4, fontsize="small")
    return fit_text(fig)


def plot_posterior(
    posterior: Posterior,
    path: str | Path,
    truth: Mapping[str, float] | None = None,
    *,
    title: str | None = None,
) -> Path:
    """Write :func:`posterior_figure` to ``path``; returns the path."""
    import matplotlib.pyplot as plt

    fig = posterior_figure(posterior, truth, title=title)
    out = Path(path)
    try:
        fig.savefig(out, dpi=120)
    finally:
        plt.close(fig)
    return out
