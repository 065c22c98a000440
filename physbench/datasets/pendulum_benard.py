"""A small rod pendulum on a hobby rig (jensen-benard 2025): three free swings, encoder angle at
a nominal 1 kHz.

Each file becomes a :class:`~physbench.datasets.recorded_run.DatasetRun` from the first extreme of
the swing (before it the hand still moves the rod; the rate there is 0). The scene is a uniform
0.13 m, 0.1 kg rod on a frictionless pivot (the plain model); the recording tracks the angle
(``fields = ("angle",)``, converted to rad; ``x, y`` are the rod centre it implies). Times are the
nominal sample index / 1000 s: the logger's real interval is >= 1 ms and jitters. For one pendulum
a clock error is a change of its inertia, so leave the rod's inertia unknown (discovery offers
:class:`~physbench.effects.ClockScale` only with a force of known size); a clock that differs from
file to file is not modelled.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from physbench.datasets.arms import Arm, chain, chain_tracks
from physbench.datasets.files import DatasetError, data_dir
from physbench.datasets.recorded_run import DatasetRun
from physbench.recording import Recording
from physbench.scene import Scene

NAME = "pendulum_benard"
FOLDER = "pendulum_benard"
PIVOT = (0.5, 0.5)
G = 9.81
ROD_LENGTH, ROD_MASS = 0.13, 0.1  # m, kg (provenance: "≈0.13 m long, ≈0.1 kg with hinge")
NOMINAL_RATE = 1000.0  # Hz
ROD = (Arm("rod", ROD_MASS, ROD_LENGTH / 2, ROD_LENGTH, ROD_MASS * ROD_LENGTH**2 / 12),)
#: Half-width (samples) of the window in which the first extreme must be the largest |angle|.
EXTREME_WINDOW = 25


def read(number: int, root: str | Path | None = None) -> tuple[np.ndarray, dict[str, float]]:
    """Angles in degrees and the header values of file ``number`` (1-3)."""
    path = data_dir(FOLDER, root) / f"pendulum_free_swing_data_{number:02d}.txt"
    if not path.is_file():
        raise DatasetError(f"no file {path}; files are numbered 1, 2, 3")
    lines = path.read_text().splitlines()
    keys = [k.strip() for k in lines[0].split(",")]
    values = [float(v) for v in lines[1].split(",")]
    angles = np.loadtxt(path, skiprows=2)
    return angles, dict(zip(keys, values, strict=True))


def first_extreme(angles: np.ndarray) -> int:
    """Index of the first sample whose |angle| is the largest within ±:data:`EXTREME_WINDOW`."""
    mag = np.abs(angles)
    for i in range(EXTREME_WINDOW, mag.size - EXTREME_WINDOW):
        win = mag[i - EXTREME_WINDOW : i + EXTREME_WINDOW + 1]
        if mag[i] == win.max() and mag[i] > win.min():
            return i
    raise DatasetError("no swing extreme found")


def load(
    files: Iterable[int] = (1, 2, 3),
    *,
    every: int = 5,
    root: str | Path | None = None,
    fps: float = 200.0,
    substeps: int = 5,
) -> list[DatasetRun]:
    """One run per file, keeping every ``every``-th sample from the first extreme on."""
    cases = []
    for number in files:
        deg, header = read(number, root)
        i0 = first_extreme(deg)
        idx = np.arange(i0, deg.size, max(1, int(every)))
        t = (idx - i0) / NOMINAL_RATE
        phi = np.radians(deg[idx])[:, None]
        bodies, joints = chain(PIVOT, ROD, phi[0], [0.0])
        rec = Recording(
            chain_tracks(PIVOT, ROD, t, phi),
            run=f"free_swing_{number:02d}",
            fields=("angle",),
            source=FOLDER,
            meta={"file": number, "first_sample": int(i0), "header": header},
        )
        scene = Scene(
            name=f"pendulum_benard_{number:02d}",
            bodies=bodies,
            bounds=(0.0, 0.0, 1.0, 1.0),
            gravity=(0.0, -G),
            fps=fps,
            frames=rec.frames_for(fps),
            substeps=substeps,
            joints=joints,
            description=(
                f"rod pendulum free swing {number} from {math.degrees(phi[0, 0]):.0f}° "
                "(jensen-benard)"
            ),
            meta={"dataset": NAME},
        ).validate()
        notes = {
            "nominal_rate_hz": NOMINAL_RATE,
            "small_angle_period_s": 2 * math.pi * math.sqrt(2 * ROD_LENGTH / (3 * G)),
        }
        effects = (
            "joint_viscous_damping",
            "joint_coulomb_friction",
            "joint_quadratic_damping",
            "sensor_offset",
            "clock_scale",
        )
        cases.append(DatasetRun(rec.run, scene, rec, effects, notes))
    return cases
