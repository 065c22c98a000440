"""No text of a figure physbench draws lies outside the figure (issue 28: titles and legends were
cut at the image's edge): :func:`physbench.plotting.layout.fit_text` on a figure built to
overflow, and every figure of ``physbench run --plot`` and of the discovery report (the sweep
figures: tests/bench/test_plots.py)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from physbench.loop import History, Iteration

LONG = "a title far wider than its figure, " * 3


def _overflowing(legend: str) -> Any:
    """A small figure with titles wider than it and a legend of 7 long entries, made in one row
    (``legend="raw"``) or by :func:`~physbench.plotting.layout.legend_below`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from physbench.plotting.layout import legend_below

    fig, ax = plt.subplots(figsize=(4, 3), layout="constrained")
    for i in range(7):
        ax.plot([0, 1], [i, i + 1], label=f"estimator number {i} (with options)")
    ax.set_title(LONG)
    fig.suptitle(LONG + "\nand a second line " + "x" * 40)
    if legend == "raw":
        fig.legend(loc="outside lower center", ncols=7)
    else:
        legend_below(fig, *ax.get_legend_handles_labels(), ncols=7)
    return fig


@pytest.mark.parametrize("legend", ["raw", "below"])
def test_an_overflowing_figure_is_fitted(texts_outside: Any, legend: str) -> None:
    from physbench.plotting.layout import fit_text

    fig = _overflowing(legend)
    with warnings.catch_warnings():  # the overflow may squeeze the axes to nothing
        warnings.simplefilter("ignore", UserWarning)
        assert texts_outside(fig)  # the check sees the overflow
    fit_text(fig)
    assert texts_outside(fig) == []
    assert "\n" in fig.axes[0].get_title()  # wrapped
    width = fig.get_size_inches()[0]
    if legend == "raw":  # a legend made too wide: the figure grows to hold it
        assert width > 10
    else:  # fewer columns: the figure keeps about its width
        assert fig.legends[0]._ncols < 7 and width < 4.5


def _history(estimator: str, seed: int) -> History:
    rng = np.random.default_rng(seed)
    loss = [float(v) for v in np.minimum.accumulate(rng.random(6))]
    iterations = [
        Iteration(i, {"a.mass": 3.0, "b.mass": 4.0}, v, v, i, v, v, 0.01, 0.01, 0.001)
        for i, v in enumerate(loss)
    ]
    meta = {"scene": "three_circles", "simulator": "pymunk", "observe_engine": "box2d"}
    meta |= {"renderer": "camera", "resolution": 640, "blur": 2.5, "noise": 0.05}
    truth = {"a.mass": 3.5, "b.mass": 4.5}
    return History(iterations, ("a.mass", "b.mass"), estimator, seed, truth, truth=truth, meta=meta)


def test_the_run_figures_fit(texts_outside: Any) -> None:
    from physbench.plotting.convergence import convergence_figure, run_title
    from physbench.plotting.posterior import posterior_figure
    from physbench.posterior.samples import Posterior

    labels = ["resnet3d(threads=1, posterior_samples=64)", "optuna(sampler=cmaes)", "tpe"]
    groups = {label: [_history(label, s) for s in range(3)] for label in labels}
    fig = convergence_figure(groups, title=run_title(groups[labels[0]][0]))
    assert texts_outside(fig) == []
    samples = np.random.default_rng(0).uniform(2, 8, size=(200, 3))
    post = Posterior(("a.mass", "b.mass", "c.elasticity_of_the_third_body"), samples, (2,) * 3,
                     (8,) * 3, "smc")  # fmt: skip
    assert texts_outside(posterior_figure(post, {"a.mass": 3.0}, title=LONG)) == []


def test_the_discovery_report_figures_fit(tmp_path: Path, slide: Any, texts_outside: Any) -> None:
    import physbench
    from physbench.discover import report
    from physbench.effects import LinearDrag
    from physbench.recording import Recording
    from physbench.simulators.pymunk_sim import PymunkSimulator

    rec = Recording.from_trajectory(PymunkSimulator().simulate(slide, effects=[LinearDrag(c=0.3)]))
    disc = physbench.discover_effects(rec, slide, effects=["linear_drag", "constant_force"])
    drawn: list[Any] = []
    save = report._Report.save

    def keep(self: Any, fig: Any, name: str, caption: str) -> tuple[str, str]:
        drawn.append((name, fig))
        return save(self, fig, name, caption)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(report._Report, "save", keep)
        report.write_report(disc, tmp_path)
    assert len(drawn) >= 3
    assert {name: texts_outside(fig) for name, fig in drawn} == {name: [] for name, _ in drawn}
