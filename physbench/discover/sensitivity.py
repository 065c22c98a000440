"""What the data can see of each parameter: how much the residuals move when a parameter moves.

Discovery drops nuisance parameters the data cannot see (:func:`prune_nuisance`), does not fit an
effect parameter that changes nothing (:func:`visible`), and sizes each new effect parameter's
steps from its sensitivity per unit (:func:`unit_sensitivity`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from physbench.discover.model import Model
from physbench.discover.residuals import rms
from physbench.errors import SimulationError


def response(
    model: Model, role: str, key: str, share: float, runs: Sequence[int] | None = None
) -> tuple[float, float]:
    """RMS change of the residuals of ``role`` when ``key`` moves ``share`` of its range inwards
    (inf when that move breaks the simulation), and the move."""
    p = model.param(key)
    base = model.residuals(role, None, runs)
    step = share * (p.high - p.low) if p.high > p.low else p.scale
    v = model.values[key]
    probe = v + step if v + step <= p.high else v - step
    try:
        moved = model.residuals(role, {key: probe}, runs)
    except SimulationError:
        return math.inf, step
    return rms(moved - base), step


def sensitivity(model: Model, role: str, key: str, runs: Sequence[int] | None = None) -> float:
    """RMS change of the residuals of ``role`` when ``key`` moves 5 % of its range inwards
    (inf when that move breaks the simulation)."""
    return response(model, role, key, 0.05, runs)[0]


def visible(model: Model, key: str) -> bool:
    """Whether moving ``key`` changes the fitted residuals at all (trying 5 %, 0.5 % and 0.05 % of
    its range: a large move of a force on a light body can throw it out of the world)."""
    for share in (0.05, 0.005, 0.0005):
        change, _ = response(model, "fit", key, share)
        if math.isfinite(change):
            return change > 1e-12
    return False


def unit_sensitivity(model: Model, key: str, rough: bool) -> float:
    """Residual RMS change per unit of ``key``: from a move of 5 % of its range, or (when that
    breaks the simulation, or saturates in a smooth scene) from 1 % or 0.1 % moves. Rough scenes
    keep the largest move that simulates, which averages over the contact saw-tooth."""
    out = []
    for share in (0.05, 0.01, 0.001):
        change, step = response(model, "fit", key, share)
        if math.isfinite(change) and change > 0:
            out.append(change / step)
            if rough or (len(out) > 1 and out[-1] < 2 * out[-2]):
                break
    return out[-1] if out else math.nan


def prune_nuisance(model: Model) -> Model:
    """``model`` without the nuisance parameters the data cannot see (e.g. x0 of a ball tracked
    only in y): a training run's on the fitted part, a held-out run's on its lead-in."""
    split = model.problem.split
    keep = []
    for p in model.params:
        if p.kind == "nuisance":
            role = "fit" if p.run in split.train_runs else "lead"
            runs = [p.run] if role == "lead" and p.run is not None else None
            if sensitivity(model, role, p.key, runs) <= 1e-12:
                continue
        keep.append(p)
    m = Model(model.problem, model.effects, keep)
    m.values.update({k: v for k, v in model.values.items() if k in m.values})
    return m
