"""The convergence figure: one panel per known error (normalized MSE of the best-by-image iterate
only when every run knows its truth, image MSE always), one line per label at the median of its
runs cut to the shortest, with the interquartile range shaded for several runs; histories group by
estimator unless labelled. Axes carry units, iterations are numbered as in the run's table, the
legend sits outside the axes and a run's title names its seed, engine and blur."""

from __future__ import annotations

import struct
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from physbench.loop import History, Iteration
from physbench.plotting.convergence import convergence_figure, plot_convergence, run_title

PNG = b"\x89PNG\r\n\x1a\n"


def _history(
    estimator: str, best_loss: Sequence[float], best_nmse: Sequence[float] | None
) -> History:
    """A history whose best-so-far curves are given (``best_nmse=None``: the truth is unknown)."""
    iterations = [
        Iteration(
            iteration=i,
            params={"a.mass": 1.0},
            loss=loss,
            nmse=None if best_nmse is None else best_nmse[i],
            best_iteration=i,
            best_loss=loss,
            best_nmse=None if best_nmse is None else best_nmse[i],
            t_simulate=0.0,
            t_render=0.0,
            t_estimator=0.0,
        )
        for i, loss in enumerate(best_loss)
    ]
    truth = None if best_nmse is None else {"a.mass": 1.0}
    return History(iterations, ("a.mass",), estimator, 0, {"a.mass": 2.0}, truth=truth)


def _png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data.startswith(PNG)
    return struct.unpack(">II", data[16:24])


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[Any]]:
    """The figures ``plot_convergence`` draws, kept open for inspection."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    close = plt.close
    kept: list[Any] = []
    monkeypatch.setattr(plt, "close", kept.append)
    yield kept
    for fig in kept:
        close(fig)


def test_with_truth_both_errors_are_drawn(tmp_path: Path) -> None:
    h = _history("tpe", [4.0, 2.0, 1.0], [0.3, 0.2, 0.1])
    out = plot_convergence(h, str(tmp_path / "c.png"), title="run")
    assert out == tmp_path / "c.png" and isinstance(out, Path)
    # two panels: 6 x (2 x 2.6 + 0.6) inches at 120 dpi
    assert _png_size(out) == (720, 696)


def test_without_truth_only_the_image_error_is_drawn(tmp_path: Path) -> None:
    out = plot_convergence(_history("tpe", [4.0, 2.0, 1.0], None), tmp_path / "c.png")
    assert _png_size(out) == (720, 384)  # one panel: 6 x (2.6 + 0.6) inches


def test_one_run_without_truth_drops_the_normalized_panel_for_all(
    tmp_path: Path, figures: list[Any]
) -> None:
    plot_convergence(
        {"known": [_history("a", [1.0], [0.5])], "unknown": [_history("b", [2.0], None)]},
        tmp_path / "c.png",
    )
    (fig,) = figures
    (ax,) = fig.axes
    assert ax.get_ylabel() == "image MSE (pixel value²)"
    assert [line.get_label() for line in ax.lines] == ["known", "unknown"]


def test_lines_are_medians_per_estimator_with_the_quartiles_shaded(
    tmp_path: Path, figures: list[Any]
) -> None:
    runs = [
        _history("tpe", [4.0, 2.0, 1.0, 0.5], [0.4, 0.2, 0.1, 0.05]),
        _history("tpe", [8.0, 4.0, 2.0], [0.8, 0.4, 0.2]),
        _history("tpe", [6.0, 6.0, 3.0], [0.6, 0.6, 0.3]),
        _history("random", [5.0, 5.0, 5.0], [0.5, 0.5, 0.5]),
    ]
    plot_convergence(runs, tmp_path / "c.png", title="three circles")
    (fig,) = figures
    top, bottom = fig.axes
    assert (top.get_ylabel(), bottom.get_ylabel()) == (
        "normalized MSE (dimensionless)",
        "image MSE (pixel value²)",
    )
    assert fig.get_suptitle() == "three circles"
    assert top.get_yscale() == bottom.get_yscale() == "log"
    assert bottom.get_xlabel() == "iteration (as numbered in the table; 0: initial guess)"
    tpe, rnd = bottom.lines
    assert tpe.get_label() == "tpe (median, IQR, n=3)" and rnd.get_label() == "random"
    # cut to the shortest run (3 iterations), the median at each iteration
    assert tpe.get_xdata().tolist() == [0, 1, 2]
    assert tpe.get_ydata().tolist() == [6.0, 4.0, 2.0]
    assert np.allclose(top.lines[0].get_ydata(), [0.6, 0.4, 0.2])
    assert len(bottom.collections) == 1  # the one band: a single run has none
    (figure_legend,) = fig.legends
    legend = [t.get_text() for t in figure_legend.get_texts()]
    assert legend == ["tpe (median, IQR, n=3)", "random"]


def test_an_unknown_suffix_is_refused_and_nothing_written(tmp_path: Path) -> None:
    # the refusal is matplotlib's: a ValueError naming the format and the supported ones
    with pytest.raises(ValueError, match=r"Format 'xyz' is not supported"):
        plot_convergence(_history("tpe", [1.0, 0.5], None), tmp_path / "c.xyz")
    assert list(tmp_path.iterdir()) == []


def test_the_normalized_panel_says_its_iterate_is_chosen_by_image_mse() -> None:
    # the curve is the normalized MSE of the best-by-image iterate, not the best normalized MSE
    fig = convergence_figure(_history("tpe", [4.0, 2.0, 1.0], [0.1, 0.3, 0.2]))
    top, bottom = fig.axes
    assert top.get_title() == "normalized MSE of the best-so-far iterate by image MSE"
    assert "best-so-far normalized MSE" not in top.get_ylabel()
    assert top.get_ylabel().endswith("(dimensionless)")
    assert bottom.get_ylabel().endswith("(pixel value²)") and "[0, 1]" in bottom.get_title()


def test_x_ticks_are_the_iteration_numbers_of_the_table() -> None:
    h = _history("tpe", [4.0, 2.0, 1.0, 0.5], [0.4, 0.2, 0.1, 0.05])
    fig = convergence_figure(h)
    bottom = fig.axes[-1]
    assert (
        bottom.lines[0].get_xdata().tolist() == [r.iteration for r in h.iterations] == [0, 1, 2, 3]
    )
    lo, hi = bottom.get_xlim()
    shown = [x for x in bottom.get_xticks() if lo <= x <= hi]
    assert shown == [0, 1, 2, 3]


def test_the_legend_lies_outside_every_axes() -> None:
    runs = [
        _history("tpe", [4.0, 2.0, 1.0], [0.4, 0.2, 0.1]),
        _history("random", [5.0, 3, 2], [0.5, 0.3, 0.2]),
    ]
    fig = convergence_figure(runs, title="t")
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert all(ax.get_legend() is None for ax in fig.axes)
    (legend,) = fig.legends
    box = legend.get_window_extent(renderer)
    assert not any(box.overlaps(ax.get_window_extent(renderer)) for ax in fig.axes)


def test_a_runs_title_names_seed_engine_and_blur() -> None:
    h = _history("tpe", [1.0], [0.5])
    h.meta.update(
        scene="three_circles",
        simulator="pymunk",
        observe_engine="mujoco",
        renderer="raster",
        resolution=32,
        blur=1.5,
        noise=0.0,
    )
    title = run_title(h)
    assert title.splitlines()[0] == "three_circles: a.mass"
    for part in ("tpe", "seed 0", "engine pymunk", "observed with mujoco", "32 px", "blur 1.5 px"):
        assert part in title
