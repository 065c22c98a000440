"""The convergence figure: one panel per known error (normalized MSE only when every run knows its
truth, image MSE always), one line per label at the median of its runs cut to the shortest, with
the interquartile range shaded for several runs; histories group by estimator unless labelled."""

from __future__ import annotations

import struct
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from physbench.loop import History, Iteration
from physbench.plotting.convergence import plot_convergence

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
    assert ax.get_ylabel() == "best-so-far image MSE"
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
        "best-so-far normalized MSE",
        "best-so-far image MSE",
    )
    assert top.get_title() == "three circles" and top.get_yscale() == bottom.get_yscale() == "log"
    assert bottom.get_xlabel() == "iterations (simulations)"
    tpe, rnd = bottom.lines
    assert tpe.get_label() == "tpe (median, IQR, n=3)" and rnd.get_label() == "random"
    # cut to the shortest run (3 iterations), the median at each iteration
    assert tpe.get_xdata().tolist() == [1, 2, 3]
    assert tpe.get_ydata().tolist() == [6.0, 4.0, 2.0]
    assert np.allclose(top.lines[0].get_ydata(), [0.6, 0.4, 0.2])
    assert len(bottom.collections) == 1  # the one band: a single run has none
    legend = [t.get_text() for t in top.get_legend().get_texts()]
    assert legend == ["tpe (median, IQR, n=3)", "random"]


def test_an_unknown_suffix_is_refused_and_nothing_written(tmp_path: Path) -> None:
    # the refusal is matplotlib's: a ValueError naming the format and the supported ones
    with pytest.raises(ValueError, match=r"Format 'xyz' is not supported"):
        plot_convergence(_history("tpe", [1.0, 0.5], None), tmp_path / "c.xyz")
    assert list(tmp_path.iterdir()) == []
