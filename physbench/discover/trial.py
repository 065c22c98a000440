"""Trying one candidate effect on top of a fitted model: extend the model, fit the extension, score
it on the held-out data and judge it against the model it extends (:func:`try_effect`).

The heuristics that make local fits of an extended model reliable live here too: new effect
parameters get steps sized from their sensitivity (:func:`rescale`), a fit in a contact scene
restarts the initial state from the data before the first impact (:func:`restart_nuisance`), and
:func:`refit` checks whether a model fits better from another model's optimum. These update a
model's values and scales in place, like the least-squares fit itself.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from physbench.discover.candidates import CandidateSpec, start_values
from physbench.discover.fit import (
    budget,
    fit_model,
    is_rough,
    least_squares,
    probe_start,
    score,
)
from physbench.discover.model import Model
from physbench.discover.residuals import EVENTS, frame_events
from physbench.discover.results import CandidateResult, FitResult, Scored, Skipped
from physbench.discover.sensitivity import unit_sensitivity, visible
from physbench.discover.settings import Settings
from physbench.discover.significance import judge
from physbench.errors import PhysbenchError, SimulationError

if TYPE_CHECKING:
    from physbench.effects.base import Effect


def try_effect(
    current: Scored,
    effect: CandidateSpec | str,
    settings: Settings | None = None,
    *,
    base: Scored | None = None,
    round: int = 1,
    quick: bool = False,
) -> CandidateResult | Skipped:
    """Fit ``current``'s model plus ``effect`` (a registered name or a :class:`CandidateSpec`)
    jointly, score it on the held-out data and judge it against ``current`` (gains against
    ``base`` too; default ``current``). Returns :class:`Skipped` when the effect does not simulate
    or the data cannot see any of its parameters. ``quick``: one horizon from the current optimum
    with a small budget (the screening fit of contact scenes)."""
    settings = settings or Settings()
    spec = effect if isinstance(effect, CandidateSpec) else CandidateSpec(effect)
    base = current if base is None else base
    trial = _extend(current, spec)
    if isinstance(trial, Skipped):
        return trial
    earlier = _rescale_steps(trial, current)
    _off_the_bounds(trial.model, trial.seen)
    if quick:
        fr = _quick_fit(trial, settings)
    else:
        fr = _full_fit(trial.model, current, settings, trial.free, trial.seen, earlier)
    fr = _no_worse_than_current(trial, current, fr)
    return judge(_candidate(trial, current, fr, round, quick), current, base, settings)


@dataclass(frozen=True)
class _Trial:
    """The current model extended by one effect (``key`` in the model): ``own`` are the effect's
    parameter keys, ``seen`` those the data can see (fitted, with the current free ones:
    ``free``), ``fixed`` the values of the others by short name."""

    effect: Effect
    key: str
    model: Model
    own: list[str]
    seen: list[str]
    fixed: dict[str, float]
    free: list[str]


def _extend(current: Scored, spec: CandidateSpec) -> _Trial | Skipped:
    """Extend ``current``'s model by the effect, started from values sized for the fitted scene,
    and find which of its parameters change the fitted data."""
    eff = spec.make()
    scene = current.model.problem.runs[0].scene
    fitted = scene.with_params(
        {p.key: current.model.values[p.key] for p in current.model.params if p.kind == "body"}
    )
    model = current.model.extended(eff, start_values(eff, fitted))
    key = eff.key
    own = [p.key for p in model.params if p.kind == "effect" and p.owner == key]
    try:
        seen = [k for k in own if visible(model, k)]
    except SimulationError as exc:
        return Skipped(spec.label, f"does not simulate: {exc}")
    if not seen:
        return Skipped(spec.label, "none of its parameters changes the fitted data")
    fixed = {k.rpartition(".")[2]: model.values[k] for k in own if k not in seen}
    return _Trial(eff, key, model, own, seen, fixed, [*current.fit.free, *seen])


def _rescale_steps(trial: _Trial, current: Scored) -> list[str]:
    """Size the steps of the effect's seen parameters, and of the causes already in the model
    outside contact scenes, to the current misfit; returns those earlier causes."""
    model = trial.model
    rough = is_rough(current.model.problem.runs)
    # The causes already in the model were scaled against the misfit of the model they extended;
    # near the current, better optimum those steps are far too large for finite differences (the
    # cause would not move and the new effect could not trade off against it): rescale them too.
    # Not in rough scenes, whose large steps are meant to average over the contact saw-tooth.
    earlier = (
        []
        if rough
        else [
            p.key
            for p in model.params
            if p.kind == "effect" and p.owner != trial.key and p.key in current.fit.free
        ]
    )
    rescale(
        model,
        {k: unit_sensitivity(model, k, rough) for k in [*trial.seen, *earlier]},
        current.fit.rms,
    )
    return earlier


def _off_the_bounds(model: Model, keys: list[str]) -> None:
    """Move each of ``keys`` at an end of its range one step inside: a bounded least-squares step
    from a bound can stall there."""
    for k in keys:
        p = model.param(k)
        v = model.values[k]
        if v <= p.low:
            model.values[k] = min(p.low + p.scale, p.high)
        elif v >= p.high:
            model.values[k] = max(p.high - p.scale, p.low)


def _quick_fit(trial: _Trial, settings: Settings) -> FitResult:
    """The screening fit: probe the new parameters, then one horizon on a small budget."""
    probe_start(trial.model, trial.seen)
    return least_squares(
        trial.model,
        trial.free,
        max_nfev=settings.max_nfev,
        budget=max(settings.quick_budget, 3 * (len(trial.free) + 1)),
        diff_step=settings.diff_step,
    )


def _no_worse_than_current(trial: _Trial, current: Scored, fr: FitResult) -> FitResult:
    """``fr``, or, when it is worse than the model it extends (the fit stalled away from the
    effect's neutral start), the current optimum with the effect switched off: the extended
    model can always do at least as well."""
    if fr.ssr <= current.fit.ssr:
        return fr
    model, free = trial.model, trial.free
    model.values = {**current.model.values, **{k: model.param(k).default for k in trial.own}}
    return FitResult(
        dict(model.values),
        list(free),
        {k: current.fit.stderr.get(k, math.nan) for k in free},
        current.fit.ssr,
        current.fit.n,
        fr.nfev,
        fr.simulations,
        "no better than the current model",
        intervals={k: v for k, v in current.fit.intervals.items() if k in free},
        interval_method=current.fit.interval_method,
    )


def _candidate(
    trial: _Trial, current: Scored, fr: FitResult, round: int, quick: bool
) -> CandidateResult:
    """Score the fitted extension on the held-out data; the result is not judged yet."""
    key, model, seen = trial.key, trial.model, trial.seen
    scored = score(f"{current.label} + {key}", (*current.causes, key), model, fr)
    return CandidateResult(
        round=round,
        effect=key,
        name=trial.effect.name,
        params={k.rpartition(".")[2]: model.values[k] for k in seen},
        stderr={k.rpartition(".")[2]: fr.stderr.get(k, math.nan) for k in seen},
        intervals={k.rpartition(".")[2]: fr.intervals[k] for k in seen if k in fr.intervals},
        interval_method=fr.interval_method,
        fixed=trial.fixed,
        heldout_error=scored.heldout,
        gain=0.0,
        gain_vs_base=0.0,
        criterion=scored.bic,
        delta_criterion=0.0,
        significant=False,
        scored=scored,
        quick=quick,
        at_bound=tuple(k.rpartition(".")[2] for k in fr.at_bound if k in seen),
        shift=_shift(trial.effect, model) if trial.effect.measures else None,
    )


def _shift(effect: Effect, model: Model) -> tuple[float, float] | None:
    """The largest change the measurement ``effect`` makes, at ``model``'s values, to a recorded
    position (m) and angle (rad) over every run's data: the engine's trajectory against the
    same with ``effect`` measured on it, both at the recording's times. ``None`` for data of
    frames, or where the measured trajectory does not cover the data."""
    position = angle = 0.0
    for i, run in enumerate(model.problem.runs):
        rec = run.recording
        if rec is None:
            return None
        try:
            traj, _ = model.simulate(i, model.values)  # sets the effect's fitted values
            plain, moved = rec.sample(traj), rec.sample(effect.measure(traj))
        except PhysbenchError:
            return None
        for body, a in plain.tracks.items():
            b = moved.tracks[body]
            position = max(position, float(np.max(np.hypot(b.x - a.x, b.y - a.y), initial=0.0)))
            if "angle" in rec.fields:
                angle = max(angle, float(np.max(np.abs(b.angle - a.angle), initial=0.0)))
    return position, angle


def _full_fit(
    model: Model,
    current: Scored,
    settings: Settings,
    free: list[str],
    seen: list[str],
    earlier: list[str],
) -> FitResult:
    """The full fit of an extended model, restarted in contact scenes, and retried once from
    further in when it stays stuck at its start on top of earlier causes."""
    if is_rough(current.model.problem.runs):
        # The current optimum's initial state was bent to make up for what the current model
        # lacks; in a contact scene that start traps the extended fit. Start it afresh.
        restart_nuisance(model, settings)
    before = dict(model.values)
    fr = fit_model(model, settings, base=False, free=free, probe=seen)
    if (
        fr.ssr > current.fit.ssr
        and earlier
        and all(abs(model.values[k] - before[k]) < 1e-3 * model.param(k).scale for k in seen)
    ):
        # Stuck where it started, on top of earlier causes: the step to where the new effect
        # trades off against them can be too long for a local fit. Once more, from further in.
        model.values = {
            **before,
            **{k: min(before[k] + 3.0 * model.param(k).scale, model.param(k).high) for k in seen},
        }
        again = fit_model(model, settings, base=False, free=free)
        if again.ssr < fr.ssr:
            fr = again
    return fr


def rescale(model: Model, sens: Mapping[str, float], target: float) -> None:
    """Give each parameter in ``sens`` the scale (optimiser unit, finite-difference unit and probe
    unit) whose change moves the residuals by about ``target`` RMS, from its sensitivity per unit
    (:func:`~physbench.discover.sensitivity.unit_sensitivity`): effect ranges are generous and say
    little about the size that matters, and a step that is too small only sees the saw-tooth of
    contact detection. Replaces ``model.params`` in place (its residual cache stays valid)."""
    out = []
    for p in model.params:
        s = sens.get(p.key, math.nan)
        if math.isfinite(s) and s > 0 and target > 0:
            span = p.high - p.low
            p = replace(p, scale=float(min(max(target / s, 1e-5 * span), 0.2 * span)))
        out.append(p)
    model.params = out


def restart_nuisance(model: Model, settings: Settings) -> None:
    """Reset the nuisance to the scene's values and fit it alone on the data before the first
    impact, where the effects at stake barely act yet (in place)."""
    nuis = [p for p in model.params if p.kind == "nuisance"]
    model.values.update({p.key: p.default for p in nuis})
    train = set(model.problem.split.train_runs)
    keys = [p.key for p in nuis if p.run in train]
    if not keys:
        return
    share = 1.0
    for part in model.problem.split.fit:
        try:
            _traj, measured = model.simulate(part.run, model.values, part.t_end)
        except SimulationError:
            continue
        ev = frame_events(model.run_scene(part.run, model.values)[0], measured)
        hits = np.nonzero((ev == EVENTS.index("impact")).any(axis=1))[0]
        t0 = float(model.problem.layouts[("fit", part.run)].t.min())
        if hits.size and part.t_end > t0:
            share = min(share, (float(measured.times[hits[0]]) - t0) / (part.t_end - t0))
    share = min(max(share * 0.9, 0.15), 0.5)
    least_squares(
        model,
        keys,
        max_nfev=settings.max_nfev,
        budget=budget(settings, len(keys)),
        diff_step=settings.diff_step,
        horizons=(share,),
        final=False,
    )


def refit(current: Scored, other: Model, settings: Settings) -> Scored | None:
    """``current``'s model refitted from ``other``'s values of the parameters they share; the
    refit when it fits better than ``current``, else None."""
    m = current.model.copy()
    m.values.update({k: v for k, v in other.values.items() if k in m.values})
    fr = fit_model(m, settings, base=False, free=current.fit.free)
    if fr.ssr >= current.fit.ssr * (1 - 1e-6):
        return None
    return score(current.label, current.causes, m, fr)
