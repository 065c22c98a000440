"""Single and double compound pendulum, encoder angles (Kaheman et al. 2022), free swing.

A :class:`~physbench.datasets.recorded_run.DatasetRun` is a window of the record: the arms'
geometry and inertia are the authors' fitted values (:data:`SINGLE`, :data:`DOUBLE`), the initial
angles and rates the data's at the window start, and the scene the plain, lossless model. The
recording tracks the arm angles (``fields = ("angle",)``); its ``x, y`` are the shape centres the
angles imply. Data angles θ (from upright, clockwise-positive as seen in the scene) map to scene
angles φ = π - θ; rates to -dθ/dt.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from physbench.datasets.arms import Arm, chain, chain_tracks
from physbench.datasets.files import DatasetError, data_dir, data_file
from physbench.datasets.recorded_run import DatasetRun
from physbench.recording import Recording
from physbench.scene import Scene

NAME = "pendulum_kaheman"
FOLDER = "pendulum_kaheman"
PIVOT = (0.5, 0.6)
G = 9.81

#: The authors' fits (EstimatedParameters_*.mat): mass, CoM distance, pivot distance, inertia.
SINGLE = (Arm("arm1", 0.14758, 0.14775, 2 * 0.14775, 1.0912e-4),)
DOUBLE = (
    Arm("arm1", 0.09384, 0.10857, 0.17272, 4.375e-4),
    Arm("arm2", 0.13760, 0.11678, 2 * 0.11678, 1.2688e-3),
)
#: The authors' linear viscous joint damping, N·m·s/rad, for reference.
AUTHORS_DAMPING = {1: (2.2394e-4,), 2: (2.371e-4, 1.0e-5)}
FILES = {1: "single_pendulum_freeswing", 2: "double_pendulum_freeswing"}


def read(arms: int, root: str | Path | None = None) -> np.ndarray:
    """Rows ``(segment, is_validation, t, theta_1..n, dtheta_1..n)`` of the full or 100 Hz copy."""
    if arms not in FILES:
        raise DatasetError(f"arms = {arms!r}: the data hold single (1) and double (2) pendulums")
    folder = data_dir(FOLDER, root)
    stem = FILES[arms]
    path = data_file(folder, f"{stem}.csv", f"{stem}_100hz.csv")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[1] != 3 + 2 * arms:
        raise DatasetError(f"{path}: expected {3 + 2 * arms} columns, got {data.shape[1]}")
    return data


def load(
    arms: int = 1,
    *,
    start: float = 0.0,
    duration: float | None = None,
    windows: int | None = None,
    every: int = 1,
    root: str | Path | None = None,
    fps: float = 100.0,
    substeps: int = 10,
) -> list[DatasetRun]:
    """Runs of ``arms`` (1 or 2): consecutive windows of ``duration`` s from ``start`` (default:
    one window to the end), at most ``windows`` of them, keeping every ``every``-th sample."""
    data = read(arms, root)
    t_all = data[:, 2]
    end = float(t_all[-1])
    if not 0 <= start < end:
        raise DatasetError(f"start = {start!r} s: the record spans 0..{end:g} s")
    length = end - start if duration is None else float(duration)
    if length <= 0:
        raise DatasetError(f"duration = {duration!r} s: must be > 0")
    n = max(1, int((end - start + 1e-9) // length))
    if windows is not None:
        n = min(n, int(windows))
    geometry = SINGLE if arms == 1 else DOUBLE
    cases = []
    for w in range(n):
        t0 = start + w * length
        sel = np.nonzero((t_all >= t0 - 1e-9) & (t_all <= t0 + length + 1e-9))[0][
            :: max(1, int(every))
        ]
        if sel.size < 2:
            raise DatasetError(f"window {t0:g}..{t0 + length:g} s holds {sel.size} samples")
        rows = data[sel]
        t = rows[:, 2] - rows[0, 2]
        phi = math.pi - rows[:, 3 : 3 + arms]
        rates = -rows[0, 3 + arms : 3 + 2 * arms]
        bodies, joints = chain(PIVOT, geometry, phi[0], rates)
        rec = Recording(
            chain_tracks(PIVOT, geometry, t, phi),
            run=f"{arms}arm/{rows[0, 2]:g}s",
            fields=("angle",),
            source=FOLDER,
            meta={"arms": arms, "t_start_s": float(rows[0, 2])},
        )
        scene = Scene(
            name=f"pendulum_kaheman_{arms}arm_{rows[0, 2]:g}s",
            bodies=bodies,
            bounds=(0.0, 0.0, 1.0, 1.2),
            gravity=(0.0, -G),
            fps=fps,
            frames=rec.frames_for(fps),
            substeps=substeps,
            joints=joints,
            description=(
                f"{'single' if arms == 1 else 'double'} pendulum free swing from "
                f"t = {rows[0, 2]:g} s (Kaheman et al. 2022)"
            ),
            meta={"dataset": NAME},
        ).validate()
        notes = {
            "authors_joint_damping": AUTHORS_DAMPING[arms],
            "rest_angle_offset_rad": math.pi - 3.167,
        }
        cases.append(
            DatasetRun(
                rec.run,
                scene,
                rec,
                ("joint_viscous_damping", "joint_coulomb_friction", "sensor_offset"),
                notes,
            )
        )
    return cases
