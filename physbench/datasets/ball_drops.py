"""Ball drops from ≈47 m (de Silva et al. 2020): 11 balls × 2 drops, height at 15 fps.

Each drop becomes a :class:`~physbench.datasets.recorded_run.DatasetRun` whose scene is the ball
falling under g = 9.81 m/s² without air (the plain model); the provenance says the model misses
quadratic drag. The recording tracks ``y`` only (``x`` is written as 0 and ``fields = ("y",)``).
Each drop is clipped as the authors do: at the last sample whose time step differs from the median
step by > 5 ms. The initial height and speed come from a least-squares fit of the first
:data:`FIT_SAMPLES` heights to free fall (g fixed), since single samples are noisy (rms 0.05-0.3 m).

:func:`check_drag_laws` tests the drag law without physbench's simulation or fitter: ODE fits of
each law of :data:`DRAG_LAWS` to the drops, scored on data they were not fitted on, and the
exponent of the excess deceleration (:func:`drag_exponent`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from physbench.datasets.files import DatasetError, data_dir
from physbench.datasets.recorded_run import DatasetRun
from physbench.errors import UnknownNameError
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
                f"{folder / 'balls.txt'}:{n}: expected 'name weight_oz circumference_cm', "
                f"got {line!r}"
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
    """Initial height and vertical velocity: least squares of ``h0 + v0 t - g t²/2`` on the first
    ``n`` samples."""
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
) -> list[DatasetRun]:
    """One run per (ball, drop); ``balls`` are CSV stems (see :data:`BALLS`), default all."""
    folder = data_dir(FOLDER, root)
    props = ball_properties(folder)
    names = list(BALLS) if balls is None else list(balls)
    cases = []
    for stem in names:
        if stem not in BALLS:
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
                    f"{folder / stem}.csv: drop {drop} has {rows.shape[0]} rows; "
                    f"drops: {sorted(set(data[:, 0].astype(int)))}"
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
                description=(
                    f"{stem.replace('_', ' ')}, drop {drop}, from {h0:.1f} m (de Silva et al. 2020)"
                ),
                meta={"dataset": NAME},
            ).validate()
            notes = {
                "mass_kg": mass,
                "radius_m": radius,
                "mass_and_size_assumed": assumed,
                "fit_start": {"h0_m": h0, "v0_mps": v0, "samples": FIT_SAMPLES},
                "excluded_by_authors": stem == "bowling_ball",
            }
            cases.append(DatasetRun(f"{stem}/{drop}", scene, rec, ("quadratic_drag",), notes))
    return cases


# --------------------------------------------------------------------------- drag law check

#: Laws of the extra acceleration of a falling ball (velocity ``v``, up positive) with their first
#: guess of ``k``: ``none`` 0; ``linear`` ``-k v``; ``quadratic`` ``-k |v| v``; ``constant`` ``+k``
#: (a change of g).
DRAG_LAWS: dict[str, float] = {"none": 0.0, "linear": 0.3, "quadratic": 0.02, "constant": 1.0}
#: Share of a drop fitted before scoring the rest (:func:`late_error`).
FITTED_SHARE = 0.7
#: Share of a drop whose start state is fitted when the drag comes from another drop.
START_SHARE = 0.25


def _check_law(law: str) -> None:
    if law not in DRAG_LAWS:
        raise UnknownNameError("drag law", law, DRAG_LAWS)


def drop_height(t: np.ndarray, h0: float, v0: float, law: str, k: float) -> np.ndarray:
    """Heights at times ``t`` (from 0) of a ball starting at ``h0`` with velocity ``v0`` under
    g = 9.81 m/s² and the extra acceleration of ``law`` with coefficient ``k`` (an ODE solve)."""
    from scipy.integrate import solve_ivp

    _check_law(law)

    def f(_: float, s: np.ndarray) -> list[float]:
        v = s[1]
        extra = {"none": 0.0, "linear": k * v, "quadratic": k * abs(v) * v, "constant": -k}[law]
        return [v, -G - extra]

    return solve_ivp(f, (0.0, float(t[-1])), [h0, v0], t_eval=t, rtol=1e-9, atol=1e-9).y[0]


def fit_drop(
    t: np.ndarray, h: np.ndarray, law: str, k: float | None = None
) -> tuple[float, float, float]:
    """Least-squares ``(h0, v0, k)`` of :func:`drop_height` to heights ``h`` at times ``t``;
    with ``k`` given (or for ``none``), only the start state is fitted."""
    from scipy.optimize import least_squares

    _check_law(law)
    if k is not None or law == "none":
        kk = 0.0 if k is None else k
        r = least_squares(lambda p: drop_height(t, p[0], p[1], law, kk) - h, [h[0], 0.0])
        return float(r.x[0]), float(r.x[1]), kk
    guess = DRAG_LAWS[law]
    r = least_squares(
        lambda p: drop_height(t, p[0], p[1], law, p[2]) - h,
        [h[0], 0.0, guess],
        x_scale=[1.0, 1.0, guess],
    )
    return float(r.x[0]), float(r.x[1]), float(r.x[2])


def late_error(t: np.ndarray, h: np.ndarray, law: str) -> np.ndarray:
    """Errors (model - data, m) on a drop's samples after :data:`FITTED_SHARE` of its duration,
    from ``law`` fitted to the samples before."""
    m = t <= FITTED_SHARE * t[-1]
    h0, v0, k = fit_drop(t[m], h[m], law)
    return drop_height(t, h0, v0, law, k)[~m] - h[~m]


def transfer_error(t: np.ndarray, h: np.ndarray, law: str, k: float) -> np.ndarray:
    """Errors (model - data, m) on a drop's samples after :data:`START_SHARE` of its duration,
    with the coefficient ``k`` fitted elsewhere and only the start state fitted to the samples
    before."""
    m = t <= START_SHARE * t[-1]
    h0, v0, _ = fit_drop(t[m], h[m], law, k)
    return drop_height(t, h0, v0, law, k)[~m] - h[~m]


def drag_exponent(
    t: np.ndarray, h: np.ndarray, window: int = 15, step: int = 5, min_speed: float = 3.0
) -> float:
    """Exponent ``n`` of the excess deceleration ``g + a ~ |v|^n`` of a drop: ``a`` and ``v`` from
    parabolas fitted to ``window`` samples every ``step`` samples, a line fitted in log-log to
    those faster than ``min_speed`` m/s with positive excess. NaN with fewer than 3 such."""
    v, dec = [], []
    mid = window // 2
    for i in range(0, len(t) - window, step):
        p = np.polyfit(t[i : i + window] - t[i + mid], h[i : i + window], 2)
        v.append(-p[1])
        dec.append(G + 2 * p[0])
    va, da = np.array(v), np.array(dec)
    ok = (va > min_speed) & (da > 0)
    if ok.sum() <= 2:
        return math.nan
    return float(np.polyfit(np.log(va[ok]), np.log(da[ok]), 1)[0])


def _rms(errors: list[np.ndarray]) -> float:
    return float(np.sqrt(np.mean(np.concatenate(errors) ** 2)))


@dataclass(frozen=True)
class DragLawCheck:
    """Per law of :data:`DRAG_LAWS`: the rms error (m) of :func:`late_error` over the drops
    (``time_split``), of :func:`transfer_error` with ``k`` from the other drop (``run_split``),
    and ``k`` fitted to each whole drop; and :func:`drag_exponent` per drop."""

    time_split: dict[str, float]
    run_split: dict[str, float]
    k: dict[str, list[float]]
    exponent: list[float]


def check_drag_laws(drops: Sequence[tuple[np.ndarray, np.ndarray]]) -> DragLawCheck:
    """:class:`DragLawCheck` of two drops ``(t, h)`` of one ball (each scored with the other's
    drag)."""
    if len(drops) != 2:
        raise DatasetError(f"check_drag_laws needs 2 drops of one ball, got {len(drops)}")
    time_split, run_split, ks = {}, {}, {}
    for law in DRAG_LAWS:
        k = [fit_drop(t, h, law)[2] for t, h in drops]
        late = [late_error(t, h, law) for t, h in drops]
        other = [transfer_error(t, h, law, k[1 - i]) for i, (t, h) in enumerate(drops)]
        time_split[law], run_split[law], ks[law] = _rms(late), _rms(other), k
    return DragLawCheck(time_split, run_split, ks, [drag_exponent(t, h) for t, h in drops])
