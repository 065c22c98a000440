r"""ParamSpace: the unknowns of a run (:class:`~physbench.parameter.Parameter`\ s), their ranges
and normalisation.

Values travel as ``{"body.param": value}`` dicts (:data:`Params`); estimators that want vectors use
:meth:`ParamSpace.to_unit` / :meth:`ParamSpace.from_unit` (each range mapped to [0, 1]).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError, UnknownNameError
from physbench.parameter import Parameter

if TYPE_CHECKING:
    from physbench.scene import Scene

Params = dict[str, float]

#: Share of an unknown's range from either end within which an estimate counts as at its bound.
AT_BOUND = 1e-3


def split_params(value: str | Sequence[str]) -> tuple[str, ...]:
    """The unknown names of one set as the user spelled it: ``"mass+elasticity"``,
    ``"mass,elasticity"``, ``"mass elasticity"`` or ``["mass", "elasticity"]`` (each item split the
    same way). Called by ``run --params``, ``train --params`` and a sweep spec's ``unknowns``;
    an empty set or a repeated name is a :class:`~physbench.errors.PhysbenchError`."""
    items = [value] if isinstance(value, str) else list(value)
    names = tuple(n for item in items for n in item.replace("+", " ").replace(",", " ").split())
    if not names or len(set(names)) != len(names):
        raise PhysbenchError(
            f"unknown-parameter set {value!r}: expected names such as mass, mass+elasticity, "
            "mass,elasticity or mass elasticity (no repeats)"
        )
    return names


@dataclass(frozen=True)
class ParamSpace:
    """An ordered set of unknowns. Order is the vector order everywhere."""

    unknowns: tuple[Parameter, ...]

    def __post_init__(self) -> None:
        if not self.unknowns:
            raise PhysbenchError("a parameter space needs at least one unknown")

    @classmethod
    def from_scene(
        cls, scene: Scene, params: Iterable[str] | None = None, bodies: Iterable[str] | None = None
    ) -> ParamSpace:
        """The scene's unknowns, filtered to parameter names (``mass``) and/or bodies.

        Raises :class:`UnknownNameError` for a parameter or body the scene does not declare unknown.
        """
        unknowns = list(scene.unknowns)
        if not unknowns:
            raise PhysbenchError(f"scene {scene.name!r} declares no unknown parameters")
        if params is not None:
            params = list(params)
            known = sorted({u.name for u in unknowns})
            for p in params:
                if p not in known:
                    raise UnknownNameError("parameter", p, known, where=f"of scene {scene.name!r}")
            unknowns = [u for u in unknowns if u.name in params]
        if bodies is not None:
            bodies = list(bodies)
            known = sorted({u.owner for u in unknowns})
            for b in bodies:
                if b not in known:
                    raise UnknownNameError(
                        "body", b, known, where=f"with unknowns in scene {scene.name!r}"
                    )
            unknowns = [u for u in unknowns if u.owner in bodies]
        return cls(tuple(unknowns))

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(u.key for u in self.unknowns)

    @property
    def bodies(self) -> tuple[str, ...]:
        """Bodies with at least one unknown, in first-appearance order."""
        return tuple(dict.fromkeys(u.owner for u in self.unknowns))

    @property
    def low(self) -> np.ndarray:
        return np.array([u.low for u in self.unknowns])

    @property
    def high(self) -> np.ndarray:
        return np.array([u.high for u in self.unknowns])

    def __len__(self) -> int:
        return len(self.unknowns)

    def to_vector(self, params: Mapping[str, float]) -> np.ndarray:
        try:
            return np.array([float(params[k]) for k in self.keys])
        except KeyError as exc:
            raise UnknownNameError("parameter", str(exc.args[0]), self.keys) from None

    def from_vector(self, vec: Sequence[float] | np.ndarray) -> Params:
        vec = np.asarray(vec, dtype=float).reshape(-1)
        if vec.shape[0] != len(self):
            raise PhysbenchError(
                f"expected {len(self)} values for {list(self.keys)}, got {vec.shape[0]}"
            )
        return {k: float(v) for k, v in zip(self.keys, vec, strict=True)}

    def to_unit(self, params: Mapping[str, float]) -> np.ndarray:
        return (self.to_vector(params) - self.low) / (self.high - self.low)

    def from_unit(self, unit: Sequence[float] | np.ndarray) -> Params:
        u = np.clip(np.asarray(unit, dtype=float), 0.0, 1.0)
        return self.from_vector(self.low + u * (self.high - self.low))

    def clip(self, params: Mapping[str, float]) -> Params:
        return self.from_vector(np.clip(self.to_vector(params), self.low, self.high))

    def contains(self, params: Mapping[str, float]) -> bool:
        v = self.to_vector(params)
        return bool(np.all(v >= self.low - 1e-12) and np.all(v <= self.high + 1e-12))

    def at_bound(self, params: Mapping[str, float], tolerance: float = AT_BOUND) -> tuple[str, ...]:
        """The keys of ``params`` within ``tolerance`` of their range's width from either end: an
        estimate there may be held by the range rather than by the data."""
        u = self.to_unit(params)
        return tuple(k for k, x in zip(self.keys, u, strict=True) if min(x, 1 - x) <= tolerance)

    def sample(self, rng: np.random.Generator) -> Params:
        """Uniform draw inside the ranges."""
        return self.from_unit(rng.random(len(self)))

    def normalized_mse(self, estimate: Mapping[str, float], truth: Mapping[str, float]) -> float:
        """The paper's metric: each parameter divided by the maximum of its range, MSE over
        unknowns."""
        d = (self.to_vector(estimate) - self.to_vector(truth)) / self.high
        return float(np.mean(d * d))

    def subset(self, body: str) -> ParamSpace:
        return ParamSpace(tuple(u for u in self.unknowns if u.owner == body))
