"""Ball drops from ≈47 m (de Silva et al. 2020): 11 balls × 2 drops, height at 15 fps.

Each drop becomes a :class:`~physbench.datasets.Case` whose scene is the ball falling under
g = 9.81 m/s² without air (the plain model); the provenance says the model misses quadratic drag.
The recording tracks ``y`` only (``x`` is written as 0 and ``fields = ("y",)``). Each drop is clipped
as the authors do: at the last sample whose time step differs from the median step by > 5 ms.
The initial height and speed come from a least-squares fit of the first :data:`FIT_SAMPLES` heights
to free fall (g fixed), since single samples are noisy (rms 0.05-0.3 m).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from physbench.datasets import Case, DatasetError, data_dir
from physbench.recording import Recording, Track
from physbench.scene import Body, Circle, Scene

NAME = "ball_drops"
FOLDER = "ball_drops_desilva"
G = 9.81
OZ = 0.0283495  # kg per ounce, as the authors convert
FIT_SAMPLES = 6
CLIP_TOLERANCE = 0.005  # s

#: CSV stem -> name in balls.txt.
BALLS = {
    "baseball": "baseball",
    "blue_basketball": "bluebasketball",
    "green_basketball": "greenbasketball",
    "volleyball": "volleyball",
    "bowling_ball": "bowlingball",
    "golf_ball": "golfball",
    "tennis_ball": "tennisball",
    "whiffle_ball_1": "wiffleball1",
    "whiffle_ball_2": "wiffleball2",
    "yellow_whiffle_ball": "yellowWiffle",
    "orange_whiffle_ball": "orangeWiffle",
}
#: The volleyball's weight and size are not recorded ("??"); a regulation ball is assumed.
VOLLEYBALL_ASSUMED = (0.27, 0.66)  # kg, circumference m


def ball_properties(folder: Path) -> dict[str, tuple[float, float] | None]:
    """balls.txt name -> (mass kg, radius m), or None where the file says ``??``."""
    out: dict[str, tuple[float, float] | None] = {}
    lines = (folder / "balls.txt").read_text().splitlines()
    for n, line in enumerate(lines[1:], start=2):
        parts = line.split()
        if not parts:
            continue
        if len(parts) != 3:
            raise DatasetError(
                f"{folder / 'balls.txt'}:{n}: expected 'name weight_oz circumference_cm', got {line!r}"
            )
        name, oz, cm = parts
        out[name] = None if "?" in oz + cm else (float(oz) * OZ, float(cm) / (200 * math.pi))
    return out


def clip_drop(t: np.ndarray) -> int:
    """Number of samples kept: up to and including the sample before the last irregular step."""
    dt = np.diff(t)
    bad = np.nonzero(np.abs(dt - np.median(dt)) > CLIP_TOLERANCE)[0]
    return int(bad[-1]) + 1 if bad.size else int(t.size)


def fit_start(t: np.ndarray, h: np.ndarray, n: int = FIT_SAMPLES) -> tuple[float, float]:
    """Initial height and vertical velocity: least squares of ``h0 + v0 t - g t²/2`` on ``n`` samples."""
    tt, hh = t[:n] - t[0], h[:n]
    a = np.stack([np.ones_like(tt), tt], axis=1)
    (h0, v0), *_ = np.linalg.lstsq(a, hh + 0.5 * G * tt**2, rcond=None)
    return float(h0), float(v0)


def load(
    balls: Iterable[str] | None = None,
    drops: Iterable[int] = (1, 2),
    *,
    root: str | Path | None = None,
    fps: float = 15.0,
    substeps: int = 20,
) -> list[Case]:
    """One case per (ball, drop); ``balls`` are CSV stems (see :data:`BALLS`), default all."""
    folder = data_dir(FOLDER, root)
    props = ball_properties(folder)
    names = list(BALLS) if balls is None else list(balls)
    cases = []
    for stem in names:
        if stem not in BALLS:
            from physbench.errors import UnknownNameError

            raise UnknownNameError("ball", stem, BALLS)
        data = np.loadtxt(folder / f"{stem}.csv", delimiter=",", skiprows=1, ndmin=2)
        prop = props.get(BALLS[stem])
        assumed = prop is None
        mass, radius = (
            prop
            if prop is not None
            else (VOLLEYBALL_ASSUMED[0], VOLLEYBALL_ASSUMED[1] / (2 * math.pi))
        )
        for drop in drops:
            rows = data[data[:, 0] == drop]
            if rows.shape[0] < FIT_SAMPLES:
                raise DatasetError(
                    f"{folder / stem}.csv: drop {drop} has {rows.shape[0]} rows; drops: {sorted(set(data[:, 0].astype(int)))}"
                )
            keep = clip_drop(rows[:, 1])
            t = rows[:keep, 1] - rows[0, 1]
            h = rows[:keep, 2]
            h0, v0 = fit_start(t, h)
            rec = Recording(
                {"ball": Track(t, np.zeros_like(t), h)},
                run=f"{stem}/{drop}",
                fields=("y",),
                source=f"{FOLDER}/{stem}.csv",
                meta={"ball": stem, "drop": drop, "samples_clipped": rows.shape[0] - keep},
            )
            scene = Scene(
                name=f"ball_drop_{stem}_{drop}",
                bodies=(Body("ball", Circle(radius), (0.0, h0), velocity=(0.0, v0), mass=mass),),
                bounds=(-2.0, 0.0, 2.0, 60.0),
                gravity=(0.0, -G),
                fps=fps,
                frames=rec.frames_for(fps),
                substeps=substeps,
                description=f"{stem.replace('_', ' ')}, drop {drop}, from {h0:.1f} m (de Silva et al. 2020)",
                meta={"dataset": NAME},
            ).validate()
            notes = {
                "mass_kg": mass,
                "radius_m": radius,
                "mass_and_size_assumed": assumed,
                "fit_start": {"h0_m": h0, "v0_mps": v0, "samples": FIT_SAMPLES},
                "excluded_by_authors": stem == "bowling_ball",
            }
            cases.append(Case(f"{stem}/{drop}", scene, rec, ("quadratic_drag",), notes))
    return cases
