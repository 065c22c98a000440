"""A decaying oscillation measured from its samples: the value it swings about, the duration of
its swings, its peaks, and the law by which its amplitude decays.

Used on the pendulum data sets' angles, and by discovery's diagnostics on any oscillating field.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

#: Loss laws of the amplitude A per half swing, ``dA = b + a·A + q·A²``: the columns (0: b,
#: 1: a, 2: q) each law fits. Coulomb friction loses a constant amount per swing, viscous damping
#: an amount proportional to the amplitude, quadratic damping one proportional to its square.
LOSS_LAWS: dict[str, tuple[int, ...]] = {
    "coulomb": (0,),
    "viscous": (1,),
    "viscous + coulomb": (0, 1),
    "viscous + quadratic": (1, 2),
}


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


def half_swing_amplitudes(x: np.ndarray, distance: int, prominence: float = 0.02) -> np.ndarray:
    """Amplitude of each half swing of ``x``: half the difference between successive extremes
    (maxima and minima at least ``distance`` samples apart and ``prominence`` high), so that an
    unknown rest value cancels."""
    from scipy.signal import find_peaks

    pk = np.sort(
        np.concatenate(
            [
                find_peaks(x, distance=distance, prominence=prominence)[0],
                find_peaks(-x, distance=distance, prominence=prominence)[0],
            ]
        )
    )
    return 0.5 * np.abs(np.diff(x[pk]))


@dataclass(frozen=True)
class LossFit:
    """One loss law fitted to the decay of the amplitudes: its coefficients (in the order of the
    law's columns in :data:`LOSS_LAWS`) and the rms of the decay per half swing it leaves."""

    coef: list[float]
    rms: float


def fit_loss_laws(amplitudes: np.ndarray) -> dict[str, LossFit]:
    """Least-squares fits of each law of :data:`LOSS_LAWS` to the loss per half swing
    ``A[k] - A[k+1]`` against the mean amplitude of the two. At large amplitudes a pendulum is
    nonlinear and these shapes are only approximate."""
    amp = np.asarray(amplitudes, dtype=float)
    d_a, a_m = amp[:-1] - amp[1:], 0.5 * (amp[:-1] + amp[1:])
    m = np.stack([np.ones_like(a_m), a_m, a_m**2], axis=1)
    out = {}
    for law, cols in LOSS_LAWS.items():
        sel = m[:, list(cols)]
        coef = np.linalg.lstsq(sel, d_a, rcond=None)[0]
        out[law] = LossFit(coef.tolist(), float(np.sqrt(np.mean((d_a - sel @ coef) ** 2))))
    return out
