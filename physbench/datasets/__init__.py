"""Loaders that turn the real measured data sets into recordings plus matching scenes.

Each loader returns a list of :class:`Case`: one recorded run and a scene that reproduces its setup
(geometry, masses and initial state from the data; the plain rigid-body model otherwise), so that
simulating ``case.scene`` and calling ``case.recording.residuals(traj)`` measures what the plain
model misses. The data live in ``benchmarks/data/<dataset>/`` of the repository, each folder with
its PROVENANCE.md; ``PHYSBENCH_DATA`` or a loader's ``root`` argument points elsewhere.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from physbench.errors import PhysbenchError, UnknownNameError
from physbench.recording import Recording
from physbench.scene import Scene

#: Environment variable naming a folder that holds the data set folders.
DATA_ENV = "PHYSBENCH_DATA"


class DatasetError(PhysbenchError, ValueError):
    """A data file that is missing or does not hold what its provenance says."""


@dataclass(frozen=True, eq=False)
class Case:
    """One recorded run and the scene that reproduces its setup.

    ``expected_effects`` names the effects (registered names) that the provenance says the plain
    model misses, for checking what discovery finds; ``notes`` holds assumptions and reference values.
    """

    name: str
    scene: Scene
    recording: Recording
    expected_effects: tuple[str, ...] = ()
    notes: Mapping[str, object] = field(default_factory=dict)


def data_dir(dataset: str, root: str | Path | None = None) -> Path:
    """The folder of ``dataset``: under ``root``, else under ``$PHYSBENCH_DATA``, else under the
    repository's ``benchmarks/data``."""
    if root is not None:
        base = Path(root)
    elif os.environ.get(DATA_ENV):
        base = Path(os.environ[DATA_ENV])
    else:
        base = Path(__file__).resolve().parents[2] / "benchmarks" / "data"
    folder = base / dataset
    if not folder.is_dir():
        raise DatasetError(
            f"data set folder {str(folder)!r} not found; pass root=... or set {DATA_ENV} to the folder "
            f"that holds {dataset}/ (the repository keeps it under benchmarks/data)"
        )
    return folder


def data_file(folder: Path, *names: str) -> Path:
    """The first of ``names`` that exists in ``folder`` (e.g. a file or its .gz copy)."""
    for n in names:
        if (folder / n).is_file():
            return folder / n
    raise DatasetError(f"none of {', '.join(names)} in {str(folder)!r}")


def _up_crossings(t: np.ndarray, d: np.ndarray) -> np.ndarray:
    i = np.nonzero((d[:-1] < 0) & (d[1:] >= 0))[0]
    return t[i] - d[i] * (t[i + 1] - t[i]) / (d[i + 1] - d[i])


def _extremes(a: np.ndarray, c: float) -> np.ndarray:
    """Indices of the largest deviation from ``c`` in each complete half swing."""
    d = a - c
    sign = np.sign(d)
    cross = np.nonzero(sign[:-1] * sign[1:] < 0)[0] + 1
    return np.array(
        [lo + int(np.argmax(np.abs(d[lo:hi]))) for lo, hi in itertools.pairwise(cross)], dtype=int
    )


def oscillation_centre(t: np.ndarray, a: np.ndarray) -> float:
    """The value a decaying signal oscillates about: the median over successive extremes ``e`` of
    ``(e[k] + 2 e[k+1] + e[k+2]) / 4``, which cancels an amplitude that shrinks linearly. A plain
    time average is biased by the decay (by about the decrement per swing)."""
    c = float(np.mean(a))
    for _ in range(3):
        e = a[_extremes(a, c)]
        if e.size < 3:
            break
        c = float(np.median((e[:-2] + 2 * e[1:-1] + e[2:]) / 4))
    return c


def oscillation_periods(t: np.ndarray, a: np.ndarray, centre: float | None = None) -> np.ndarray:
    """Durations of the successive full swings of a signal, from its upward crossings of
    ``centre`` (default: :func:`oscillation_centre`), interpolated between samples."""
    c = oscillation_centre(t, a) if centre is None else centre
    return np.diff(_up_crossings(t, a - c))


def swing_peaks(
    t: np.ndarray, a: np.ndarray, centre: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Times and amplitudes (about ``centre``, default :func:`oscillation_centre`) of the extremes
    of each complete half swing."""
    c = oscillation_centre(t, a) if centre is None else centre
    k = _extremes(a, c)
    return t[k], np.abs(a[k] - c)


def _loaders() -> dict[str, Callable[..., list[Case]]]:
    from physbench.datasets import ball_drops, billiards, pendulum_benard, pendulum_kaheman

    return {m.NAME: m.load for m in (ball_drops, billiards, pendulum_kaheman, pendulum_benard)}


def dataset_names() -> list[str]:
    return sorted(_loaders())


def load(name: str, **options: object) -> list[Case]:
    """The cases of data set ``name`` (see :func:`dataset_names`); ``options`` go to its loader."""
    loaders = _loaders()
    if name not in loaders:
        raise UnknownNameError("data set", name, loaders)
    return loaders[name](**options)


__all__ = [
    "DATA_ENV",
    "Case",
    "DatasetError",
    "data_dir",
    "dataset_names",
    "load",
    "oscillation_centre",
    "oscillation_periods",
    "swing_peaks",
]
