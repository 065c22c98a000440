"""Loaders that turn the real measured data sets into recordings plus matching scenes.

Each loader returns a list of :class:`~physbench.datasets.recorded_run.DatasetRun`: one recorded
run and a scene that reproduces its setup (geometry, masses and initial state from the data; the
plain rigid-body model otherwise), so that simulating ``run.scene`` and calling
``run.recording.residuals(traj)`` measures what the plain model misses. The data ship inside the
package, ``physbench/datasets/data/<dataset>/``, each folder with its PROVENANCE.md;
``PHYSBENCH_DATA`` or a loader's ``root`` argument points elsewhere
(:mod:`~physbench.datasets.files`).

One module per data set (``NAME`` and ``load``); the shared concepts have their own modules:
:mod:`~physbench.datasets.recorded_run` (the run), :mod:`~physbench.datasets.files` (finding the
data) and :mod:`~physbench.datasets.oscillation` (measuring swings).
"""

from __future__ import annotations

from collections.abc import Callable

from physbench.datasets.files import DATA_ENV, DatasetError, data_dir
from physbench.datasets.oscillation import oscillation_centre, oscillation_periods, swing_peaks
from physbench.datasets.recorded_run import DatasetRun
from physbench.errors import UnknownNameError


def _loaders() -> dict[str, Callable[..., list[DatasetRun]]]:
    from physbench.datasets import ball_drops, billiards, pendulum_benard, pendulum_kaheman

    return {m.NAME: m.load for m in (ball_drops, billiards, pendulum_kaheman, pendulum_benard)}


def dataset_names() -> list[str]:
    return sorted(_loaders())


def load(name: str, **options: object) -> list[DatasetRun]:
    """The runs of data set ``name`` (see :func:`dataset_names`); ``options`` go to its loader."""
    loaders = _loaders()
    if name not in loaders:
        raise UnknownNameError("data set", name, loaders)
    return loaders[name](**options)


def describe(name: str) -> str:
    """One line on data set ``name``: the first line of its module's docstring."""
    import sys

    loader = _loaders().get(name)
    if loader is None:
        raise UnknownNameError("data set", name, _loaders())
    doc = sys.modules[loader.__module__].__doc__ or ""
    return doc.strip().split("\n\n")[0].replace("\n", " ")


def select(spec: str) -> list[DatasetRun]:
    """The runs ``spec`` names: ``NAME`` (every run of data set NAME, as :func:`load` gives
    them) or ``NAME/RUN`` (the runs named RUN or ``RUN/...``, e.g. ``ball_drops/whiffle_ball_1``
    for both drops of that ball); called for ``physbench datasets`` and ``discover --dataset``.
    A RUN that matches none lists the runs there are."""
    name, _, run = spec.partition("/")
    runs = load(name)
    if not run:
        return runs
    chosen = [r for r in runs if r.name == run or r.name.startswith(run.rstrip("/") + "/")]
    if not chosen:
        groups = list(dict.fromkeys(r.name.partition("/")[0] for r in runs))
        shown = ", ".join(groups[:20]) + (
            f", ... ({len(groups)} in all)" if len(groups) > 20 else ""
        )
        raise DatasetError(
            f"{spec!r}: data set {name!r} has no run {run!r}; its runs: {shown} (see "
            f"`physbench datasets {name}`)"
        )
    return chosen


__all__ = [
    "DATA_ENV",
    "DatasetError",
    "DatasetRun",
    "data_dir",
    "dataset_names",
    "describe",
    "load",
    "oscillation_centre",
    "oscillation_periods",
    "select",
    "swing_peaks",
]
