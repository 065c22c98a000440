"""Did the fit fail? Two measures of a run's best image MSE, neither of which needs the truth.

- **Against the noise floor.** When the observation's pixel noise is known (stated by the
  observation model, or estimated from the frames above an 8-bit step), the image MSE that the
  true parameters would leave is the noise's own: per pixel ``E[(clip(mu + sigma Z, 0, 1) - mu)^2]``
  at the best iterate's frames ``mu`` (:func:`noise_floor`). ``noise_ratio`` is the best image MSE
  over that floor: about 1 for a fit that reproduces the observation, and above
  :data:`NOISE_FACTOR` when the model misses it by far more than the noise.
- **Against the scene's other seeds.** A learned estimator reaches a typical image MSE on a scene
  and unknown set after a given number of iterations. ``scene_ratio`` is the run's best image MSE
  over the median of that estimator on held-out seeds of the same row, in the same setting
  (a :class:`Reference`); above :data:`SCENE_FACTOR` the fit is far from what the scene allows.
  The image MSE does not see everything the parameters do (a mass that moves few pixels), so a
  flagged fit may still be near the truth, and a fit off in such a direction goes unflagged.
  The references ship in ``failure_reference.json`` beside this module, written by
  ``benchmarks/resnet3d_failures.py`` (see that script for the seeds and setting).

Called by :func:`~physbench.experiment.run_config` after the loop; the result is
``History.fit``.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

#: The fit failed when its best image MSE exceeds the noise floor this many times.
NOISE_FACTOR = 10.0
#: The fit failed when its best image MSE exceeds the reference median this many times. Set on
#: resnet3d's Table 1 rows (benchmarks/resnet3d_failures.py, 200 held-out seeds per row, each
#: judged against the other half's median): of the iterates whose normalized MSE is above 100
#: times their row's median, 1,441 of 1,468 have an image MSE above 30 times it, while 23 of the
#: 1,600 runs end above it with a normalized MSE of 0.3 to 26 times the median.
SCENE_FACTOR = 30.0
REFERENCES = Path(__file__).with_name("failure_reference.json")


def noise_floor(frames: np.ndarray, sigma: float) -> float:
    """The mean over pixels of ``E[(clip(mu + sigma Z, 0, 1) - mu)^2]``, ``mu`` the frames: the
    image MSE that pixel noise ``sigma``, clipped to [0, 1], leaves between the observation and
    the frames that made it."""
    from scipy.special import ndtr

    mu = np.asarray(frames, dtype=np.float64)
    a, b = -mu / sigma, (1.0 - mu) / sigma
    pdf_a, pdf_b = np.exp(-0.5 * a * a), np.exp(-0.5 * b * b)
    inv = 1.0 / np.sqrt(2.0 * np.pi)
    inside = (ndtr(b) - ndtr(a)) - inv * (b * pdf_b - a * pdf_a)
    below, above = ndtr(a), 1.0 - ndtr(b)
    per_pixel = sigma**2 * inside + mu**2 * below + (1.0 - mu) ** 2 * above
    return float(per_pixel.mean())


@dataclass(frozen=True)
class Reference:
    """What an estimator reaches on a row: the median (and 99th percentile) of its best image MSE
    after ``iterations`` on ``seeds`` held-out seeds, in the setting ``setting`` (engine,
    renderer, resolution, mode, blur, noise)."""

    estimator: str
    scene: str
    unknowns: tuple[str, ...]
    iterations: int
    setting: Mapping[str, Any]
    median: float
    q99: float
    seeds: int
    weights_sha256: str = ""


@cache
def _references() -> tuple[Reference, ...]:
    if not REFERENCES.is_file():
        return ()
    rows = json.loads(REFERENCES.read_text())["references"]
    return tuple(Reference(**{**r, "unknowns": tuple(r["unknowns"])}) for r in rows)


def reference(
    estimator: str, scene: str, unknowns: tuple[str, ...], iterations: int, setting: Mapping
) -> Reference | None:
    """The shipped reference for exactly this row, budget and setting, or ``None``."""
    want = tuple(sorted(unknowns))
    for r in _references():
        if (r.estimator, r.scene, tuple(sorted(r.unknowns)), r.iterations) == (
            estimator,
            scene,
            want,
            iterations,
        ) and dict(r.setting) == dict(setting):
            return r
    return None


@dataclass(frozen=True)
class FitCheck:
    """The two measures of a run's best image MSE ``min_loss`` (see the module docstring):
    ``noise_ratio`` over ``noise_floor`` (``None`` without a known noise level) and
    ``scene_ratio`` over ``reference`` (``None`` without a reference for the run's estimator,
    row, budget and setting)."""

    min_loss: float
    noise_floor: float | None = None
    reference: float | None = None
    reference_seeds: int = 0

    @property
    def noise_ratio(self) -> float | None:
        return None if not self.noise_floor else self.min_loss / self.noise_floor

    @property
    def scene_ratio(self) -> float | None:
        return None if not self.reference else self.min_loss / self.reference

    @property
    def failed(self) -> bool:
        n, s = self.noise_ratio, self.scene_ratio
        return (n is not None and n > NOISE_FACTOR) or (s is not None and s > SCENE_FACTOR)

    def describe(self) -> str | None:
        """The sentence ``physbench run`` prints when the fit failed (``None`` otherwise)."""
        if not self.failed:
            return None
        why = []
        n, s = self.noise_ratio, self.scene_ratio
        if n is not None and n > NOISE_FACTOR:
            why.append(f"{n:.3g} times the pixel noise's own ({self.noise_floor:.3g})")
        if s is not None and s > SCENE_FACTOR:
            why.append(
                f"{s:.3g} times the median this estimator reaches on {self.reference_seeds} "
                f"other seeds of the scene ({self.reference:.3g})"
            )
        return (
            f"the fit looks failed: its best image MSE {self.min_loss:.3g} is "
            + " and ".join(why)
            + "; the estimate may be far off (more iterations, a restart from a global design, "
            "or another estimator may find the fit)"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            **asdict(self),
            "noise_ratio": self.noise_ratio,
            "scene_ratio": self.scene_ratio,
            "failed": self.failed,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> FitCheck:
        names = cls.__dataclass_fields__
        return cls(**{k: v for k, v in d.items() if k in names})
