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


__all__ = [
    "DATA_ENV",
    "DatasetError",
    "DatasetRun",
    "data_dir",
    "dataset_names",
    "load",
    "oscillation_centre",
    "oscillation_periods",
    "swing_peaks",
]
