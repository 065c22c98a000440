"""Selecting the cause: fit the base model, fit base + each candidate effect jointly, compare them on
held-out data and with an information criterion, and add effects greedily while that helps.

A candidate is *significant* when both hold, against the model it extends:

* held-out gain ``1 - heldout(extended) / heldout(current) >= min_gain``, and
* ``ΔBIC = BIC(extended) - BIC(current) <= -min_delta_bic`` on the fitted part
  (``BIC = n ln(SSR/n) + k ln n``).

The most useful significant candidate (lowest held-out error) is added; the next round refits the
``shortlist`` best remaining candidates of this round on top of it, until nothing is significant
or ``max_causes`` effects were added. Defaults were calibrated on control recordings (no hidden
effect, both engines): see ``docs/discover.md``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.discover.candidates import CandidateSpec, candidates_for, start_values
from physbench.discover.data import DiscoverError, Run, Split, make_split
from physbench.discover.fit import FitResult, estimator_fit, least_squares, probe_start
from physbench.discover.model import Model, Problem, body_params, nuisance_params
from physbench.discover.residuals import rms
from physbench.errors import SimulationError

if TYPE_CHECKING:
    from physbench.discover.diagnostics import Finding
    from physbench.discover.residuals import Breakdown
    from physbench.effects.base import Effect
    from physbench.render.base import Renderer
    from physbench.simulators.base import Simulator


@dataclass(frozen=True)
class Settings:
    """Every knob of a discovery (defaults are the calibrated ones)."""

    effects: Sequence[str] | None = None  # candidate effect names (None: every registered one)
    holdout: float = 0.3  # share of the data held out
    split: str = "auto"  # time | runs | auto
    lead: float = 0.25  # share of a held-out run that fits its initial state
    nuisance: Sequence[str] | str = "auto"
    estimator: str = "lsq"  # base fit: lsq, or a registered estimator followed by lsq
    estimator_iterations: int = 60
    estimator_options: dict[str, Any] | None = None
    seed: int = 0
    min_gain: float = 0.1
    min_delta_bic: float = 10.0
    max_causes: int = 3
    shortlist: int = 4
    max_nfev: int = 30
    base_max_nfev: int = 60
    #: Most simulations of one candidate fit per continuation horizon (the base fit gets twice).
    budget: int = 120
    #: Contact scenes: simulations of a candidate's quick screening fit, and how many candidates
    #: per round then get the full fit.
    quick_budget: int = 40
    screen: int = 3
    #: Finite-difference step in units of each parameter's scale: large enough to step over the
    #: saw-tooth that contact detection at discrete steps puts into the residuals.
    diff_step: float = 0.3
    #: Continuation horizons (shares of each fitted part, fitted in turn); None: (0.5, 1) for
    #: scenes with contacts, where late bounces make the fit multimodal, else (1,).
    horizons: Sequence[float] | None = None
    #: Candidates whose held-out error is within this factor of the chosen one's are reported as
    #: explaining the data about as well.
    ambiguity: float = 0.05

    def __post_init__(self) -> None:
        for name in ("min_gain", "ambiguity"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not 0 <= v < 1:
                raise DiscoverError(f"{name} = {v!r}: expected a number in [0, 1)")
        for name in (
            "max_causes",
            "shortlist",
            "max_nfev",
            "base_max_nfev",
            "budget",
            "quick_budget",
            "screen",
        ):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise DiscoverError(f"{name} = {v!r}: expected a whole number >= 1")
        if not isinstance(self.min_delta_bic, int | float) or self.min_delta_bic < 0:
            raise DiscoverError(f"min_delta_bic = {self.min_delta_bic!r}: expected a number >= 0")


@dataclass(eq=False)
class Scored:
    """A fitted model and how well it predicts the held-out data."""

    label: str
    causes: tuple[str, ...]
    model: Model
    fit: FitResult
    heldout: float
    heldout_n: int
    failure: str = ""

    @property
    def bic(self) -> float:
        return self.fit.bic()

    def summary(self, keys: Sequence[str] | None = None) -> dict[str, Any]:
        shown = (
            [p.key for p in self.model.params if p.kind != "nuisance"]
            if keys is None
            else list(keys)
        )
        return {
            "effects": list(self.causes),
            "params": {k: self.model.values[k] for k in shown},
            "stderr": {k: self.fit.stderr.get(k) for k in shown},
            "nuisance": {
                p.key: self.model.values[p.key] for p in self.model.params if p.kind == "nuisance"
            },
            "fit_error": self.fit.rms,
            "heldout_error": self.heldout,
            "criterion": self.bic,
            "n_fit": self.fit.n,
            "n_heldout": self.heldout_n,
            "k": self.fit.k,
            "simulations": self.fit.simulations,
        }


@dataclass(eq=False)
class CandidateResult:
    """One candidate fit: the effect added to the model of ``round`` - 1 causes."""

    round: int
    effect: str  # the effect's key (label or name)
    name: str  # registered name
    params: dict[str, float]
    stderr: dict[str, float]
    fixed: dict[str, float]
    heldout_error: float
    gain: float  # against the model it extends
    gain_vs_base: float
    criterion: float
    delta_criterion: float
    significant: bool
    chosen: bool = False
    note: str = ""
    scored: Scored | None = None
    quick: bool = False
    previous: Scored | None = None  # the model this candidate extends

    def to_dict(self) -> dict[str, Any]:
        return {
            "effect": self.effect,
            "name": self.name,
            "round": self.round,
            "params": self.params,
            "stderr": self.stderr,
            "fixed": self.fixed,
            "heldout_error": _num(self.heldout_error),
            "gain": _num(self.gain),
            "gain_vs_base": _num(self.gain_vs_base),
            "criterion": _num(self.criterion),
            "delta_criterion": _num(self.delta_criterion),
            "significant": self.significant,
            "chosen": self.chosen,
            "note": self.note,
            "quick_fit_only": self.quick,
        }


def _num(v: float) -> float | None:
    return float(v) if v is not None and math.isfinite(v) else None


@dataclass(eq=False)
class Discovery:
    """Everything a discovery found; :mod:`physbench.discover.verdict` turns it into text and JSON."""

    runs: Sequence[Run]
    split: Split
    settings: Settings
    engine: str
    unit: str
    base: Scored
    final: Scored
    candidates: list[CandidateResult]
    causes: list[str]
    gain: float
    skipped: list[tuple[str, str]]
    alternatives: dict[str, list[str]] = field(default_factory=dict)
    findings: dict[str, list[Finding]] = field(default_factory=dict)
    breakdowns: dict[str, Breakdown] = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def cause_results(self) -> list[CandidateResult]:
        return [c for c in self.candidates if c.chosen]


# --------------------------------------------------------------------------- fitting steps


def _check_unknowns(runs: Sequence[Run]) -> None:
    first = [u.key for u in runs[0].scene.unknowns]
    for r in runs[1:]:
        got = [u.key for u in r.scene.unknowns]
        if got != first:
            raise DiscoverError(
                f"run {r.name!r} declares unknowns {got} but run {runs[0].name!r} declares {first}; runs share their unknowns"
            )


def _sensitivity(model: Model, role: str, key: str, runs: Sequence[int] | None = None) -> float:
    """RMS change of the residuals of ``role`` when ``key`` moves 5 % of its range inwards
    (inf when that move breaks the simulation)."""
    return _response(model, role, key, 0.05, runs)[0]


def _response(
    model: Model, role: str, key: str, share: float, runs: Sequence[int] | None = None
) -> tuple[float, float]:
    """RMS change of the residuals when ``key`` moves ``share`` of its range inwards, and the move."""
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


def _visible(model: Model, key: str) -> bool:
    """Whether moving ``key`` changes the fitted residuals at all (trying 5 %, 0.5 % and 0.05 % of
    its range: a large move of a force on a light body can throw it out of the world)."""
    for share in (0.05, 0.005, 0.0005):
        change, _ = _response(model, "fit", key, share)
        if math.isfinite(change):
            return change > 1e-12
    return False


def _unit_sensitivity(model: Model, key: str, rough: bool) -> float:
    """Residual RMS change per unit of ``key``: from a move of 5 % of its range, or (when that
    breaks the simulation, or saturates in a smooth scene) from 1 % or 0.1 % moves. Rough scenes
    keep the largest move that simulates, which averages over the contact saw-tooth."""
    out = []
    for share in (0.05, 0.01, 0.001):
        change, step = _response(model, "fit", key, share)
        if math.isfinite(change) and change > 0:
            out.append(change / step)
            if rough or (len(out) > 1 and out[-1] < 2 * out[-2]):
                break
    return out[-1] if out else math.nan


def _prune_nuisance(model: Model) -> Model:
    """Drop nuisance parameters the data cannot see (e.g. x0 of a ball tracked only in y)."""
    split = model.problem.split
    keep = []
    for p in model.params:
        if p.kind == "nuisance":
            role = "fit" if p.run in split.train_runs else "lead"
            if _sensitivity(model, role, p.key, [p.run] if role == "lead" else None) <= 1e-12:
                continue
        keep.append(p)
    m = Model(model.problem, model.effects, keep)
    m.values.update({k: v for k, v in model.values.items() if k in m.values})
    return m


def _fit(
    model: Model,
    settings: Settings,
    *,
    base: bool,
    free: Sequence[str] | None = None,
    probe: Sequence[str] = (),
    horizons: Sequence[float] | None = None,
) -> FitResult:
    keys = model.free_keys() if free is None else list(free)
    if base and settings.estimator != "lsq" and keys:
        estimator_fit(
            model,
            keys,
            settings.estimator,
            iterations=settings.estimator_iterations,
            seed=settings.seed,
            options=settings.estimator_options,
        )
    if probe:
        probe_start(model, probe)
    fr = least_squares(
        model,
        keys,
        max_nfev=settings.base_max_nfev if base else settings.max_nfev,
        budget=_budget(settings, len(keys)) * (2 if base else 1),
        diff_step=settings.diff_step,
        horizons=horizons or _horizons(model, settings),
    )
    for i in model.problem.split.test_runs if model.problem.split.kind == "runs" else ():
        own = [p.key for p in model.params if p.kind == "nuisance" and p.run == i]
        if own:
            least_squares(
                model,
                own,
                role="lead",
                runs=[i],
                max_nfev=settings.max_nfev,
                budget=_budget(settings, len(own)),
                diff_step=settings.diff_step,
            )
    return fr


def _budget(settings: Settings, free: int) -> int:
    """Simulations per fit horizon: ``settings.budget`` for up to 7 free parameters, growing with
    the Jacobian's cost beyond."""
    return int(settings.budget * max(1.0, (free + 1) / 8))


def _rough(runs: Sequence[Run]) -> bool:
    """Whether the fit landscape is rough: bodies can hit something (static geometry, or each
    other when not jointed), so that impacts detected at discrete steps put a saw-tooth into the
    residuals, or the loss is on images, which stop pulling once shapes no longer overlap."""
    scene = runs[0].scene
    return (
        bool(scene.statics)
        or (len(scene.bodies) > 1 and not scene.joints)
        or any(r.frames is not None for r in runs)
    )


def _horizons(model: Model, settings: Settings) -> tuple[float, ...]:
    if settings.horizons is not None:
        return (*(h for h in settings.horizons if 0 < h < 1), 1.0)
    return (0.5, 1.0) if _rough(model.problem.runs) else (1.0,)


def _restart_nuisance(model: Model, settings: Settings) -> None:
    """Reset the nuisance to the scene's values and fit it alone on the data before the first
    impact, where the effects at stake barely act yet."""
    from physbench.discover.residuals import EVENTS, frame_events

    nuis = [p for p in model.params if p.kind == "nuisance"]
    model.values.update({p.key: p.start for p in nuis})
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
        budget=_budget(settings, len(keys)),
        diff_step=settings.diff_step,
        horizons=(share,),
        final=False,
    )


def _score(label: str, causes: tuple[str, ...], model: Model, fr: FitResult) -> Scored:
    try:
        r = model.residuals("held")
        held, why = rms(r), ""
    except SimulationError as exc:
        r, held, why = np.zeros(0), math.inf, str(exc)
    return Scored(label, causes, model, fr, held, int(r.size), why)


# --------------------------------------------------------------------------- discovery


def discover(
    runs: Sequence[Run],
    simulator: Simulator | str = "pymunk",
    *,
    settings: Settings | None = None,
    renderer: Renderer | None = None,
    candidates: Sequence[CandidateSpec] | None = None,
    diagnose: bool = True,
) -> Discovery:
    """Fit the base model to ``runs``, try every candidate effect, and add the significant ones
    greedily. ``candidates`` overrides the automatic choice (:func:`candidates_for`)."""
    from physbench.plugins import create

    t0 = time.perf_counter()
    settings = settings or Settings()
    sim = create("simulator", simulator) if isinstance(simulator, str) else simulator
    runs = list(runs)
    split = make_split(runs, settings.holdout, settings.split, settings.lead)
    _check_unknowns(runs)
    if renderer is None and any(r.frames is not None for r in runs):
        renderer = renderer_for(runs)
    problem = Problem(runs, split, sim, renderer)
    params = body_params(runs[0].scene)
    for i, r in enumerate(runs):
        params += nuisance_params(r, i, "" if len(runs) == 1 else f"{r.name}/", settings.nuisance)
    start = Model(problem, [], params)
    for role in ("fit", "lead", "held"):
        try:
            start.residuals(role)
        except SimulationError as exc:
            raise DiscoverError(
                f"the scene as given does not simulate over the recording ({role} part): {exc}; check the scene's "
                "bounds, initial state and frame rate against the recording"
            ) from exc
    base_model = _prune_nuisance(start)
    probe = [p.key for p in base_model.params if p.kind == "body"]
    base_fit = _fit(base_model, settings, base=True, probe=probe)
    if _rough(runs) and settings.horizons is None:
        # Contact scenes: the fit lands in the valley nearest to its start; a second schedule of
        # horizons from the scene's start often finds a lower one. Keep the better.
        other = Model(problem, [], base_model.params)
        other_fit = _fit(other, settings, base=True, probe=probe, horizons=(0.35, 0.7, 1.0))
        if other_fit.ssr < base_fit.ssr:
            base_model, base_fit = other, other_fit
    base = _score("base", (), base_model, base_fit)
    if not math.isfinite(base.heldout):
        raise DiscoverError(
            f"the fitted base model fails on the held-out data ({base.failure}); check the scene and the recording"
        )

    if candidates is None:
        specs, skipped = candidates_for(runs[0].scene, settings.effects)
        if settings.effects is not None and not specs:
            why = "; ".join(f"{n}: {r}" for n, r in skipped)
            raise DiscoverError(
                f"none of the requested effects applies to scene {runs[0].scene.name!r} ({why})"
            )
    else:
        specs, skipped = list(candidates), []
    current, causes = base, []
    results: list[CandidateResult] = []
    chosen: list[CandidateResult] = []
    alternatives: dict[str, list[str]] = {}
    pool = list(specs)
    for rnd in range(1, settings.max_causes + 1):
        contacts = _rough(runs)
        round_results = [
            c
            for c in (
                _try(spec, current, base, rnd, settings, skipped, quick=contacts) for spec in pool
            )
            if c is not None
        ]
        if contacts:
            # Rough scenes: every candidate got a quick fit from the current optimum; the most
            # promising ones (by fitted error, never by held-out error) and the ones the current
            # model's residual statistics point at get the full, restarted fit.
            from physbench.discover.diagnostics import findings, views

            suggested = {e for f in findings(views(current)) for e in f.suggests}
            ranked = sorted(
                (c for c in round_results if c.delta_criterion < 0), key=lambda c: c.criterion
            )
            chosen_full = ranked[: settings.screen] + [
                c
                for c in round_results
                if c.name in suggested and c not in ranked[: settings.screen]
            ]
            for c in chosen_full:
                spec = next(sp for sp in pool if sp.label == c.effect)
                full = _try(spec, current, base, rnd, settings, [], quick=False)
                if full is not None and full.criterion < c.criterion:
                    round_results[round_results.index(c)] = full
            for c in round_results:
                if c.quick:
                    c.note = "; ".join(filter(None, [c.note, "quick fit only (screened out)"]))
        results += round_results
        best = None
        for _ in range(3):
            good = [c for c in round_results if c.significant]
            if not good:
                break
            best = min(good, key=lambda c: (c.heldout_error, c.criterion))
            assert best.scored is not None
            # A candidate can beat the current model only because its fit escaped a valley the
            # current fit is stuck in: refit the current model from the candidate's optimum and
            # judge again against whichever fit of the current model is better.
            better = _refit(current, best.scored.model, settings)
            if better is None:
                break
            if current is base:
                base = better
            elif chosen:  # the current model is the last cause's fit: report the better one
                _update(chosen[-1], better, base, settings)
            current, best = better, None
            for c in round_results:
                _judge(c, current, base, settings)
        if best is None:
            break
        best.chosen = True
        chosen.append(best)
        causes.append(best.effect)
        alternatives[best.effect] = [
            c.effect
            for c in round_results
            if c is not best
            and c.significant
            and c.heldout_error <= best.heldout_error * (1 + settings.ambiguity)
        ]
        assert best.scored is not None
        current = best.scored
        ranked = sorted(
            (c for c in round_results if c is not best and c.gain > 0), key=lambda c: -c.gain
        )
        names = {c.effect for c in ranked[: settings.shortlist]}
        from physbench.discover.diagnostics import findings, views

        # ... and whatever the new model's residual statistics still point at
        names |= {e for f in findings(views(current)) for e in f.suggests} - {best.name}
        pool = [s for s in pool if s.label in names or s.name in names]
        if not pool:
            break
    if len(causes) > 1:
        current, causes = _eliminate(current, causes, results, settings)
    disc = Discovery(
        runs=runs,
        split=split,
        settings=settings,
        engine=str(getattr(sim, "name", type(sim).__name__)),
        unit=problem.unit,
        base=base,
        final=current,
        candidates=results,
        causes=causes,
        gain=1.0 - current.heldout / base.heldout if base.heldout > 0 else 0.0,
        skipped=skipped,
        alternatives=alternatives,
    )
    if diagnose:
        from physbench.discover.diagnostics import diagnose as run_diagnostics

        run_diagnostics(disc)
    disc.seconds = time.perf_counter() - t0
    return disc


def _try(
    spec: CandidateSpec,
    current: Scored,
    base: Scored,
    rnd: int,
    settings: Settings,
    skipped: list[tuple[str, str]],
    *,
    quick: bool = False,
) -> CandidateResult | None:
    """Fit ``current`` + the effect of ``spec``; None (and a note in ``skipped``) when the data
    cannot see any of its parameters. ``quick``: one horizon from the current optimum with a
    small budget (the screening fit of contact scenes)."""
    eff: Effect = spec.make()
    scene = current.model.problem.runs[0].scene
    fitted = scene.with_params(
        {p.key: current.model.values[p.key] for p in current.model.params if p.kind == "body"}
    )
    model = current.model.extended(eff, start_values(eff, fitted))
    key = str(getattr(eff, "key", eff.name))
    own = [p.key for p in model.params if p.kind == "effect" and p.target == key]
    try:
        visible = [k for k in own if _visible(model, k)]
    except SimulationError as exc:
        if rnd == 1:
            skipped.append((spec.label, f"does not simulate: {exc}"))
        return None
    if not visible:
        if rnd == 1:
            skipped.append((spec.label, "none of its parameters changes the fitted data"))
        return None
    fixed = {k.rpartition(".")[2]: model.values[k] for k in own if k not in visible}
    free = [*current.fit.free, *visible]
    rough = _rough(current.model.problem.runs)
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
            if p.kind == "effect" and p.target != key and p.key in current.fit.free
        ]
    )
    _rescale(
        model,
        {k: _unit_sensitivity(model, k, rough) for k in [*visible, *earlier]},
        current.fit.rms,
    )
    for k in visible:  # off the bound: a bounded least-squares step from a bound can stall there
        p = model.param(k)
        v = model.values[k]
        if v <= p.low:
            model.values[k] = min(p.low + p.scale, p.high)
        elif v >= p.high:
            model.values[k] = max(p.high - p.scale, p.low)
    if quick:
        probe_start(model, visible)
        fr = least_squares(
            model,
            free,
            max_nfev=settings.max_nfev,
            budget=max(settings.quick_budget, 3 * (len(free) + 1)),
            diff_step=settings.diff_step,
        )
    else:
        if _rough(current.model.problem.runs):
            # The current optimum's initial state was bent to make up for what the current model
            # lacks; in a contact scene that start traps the extended fit. Start it afresh.
            _restart_nuisance(model, settings)
        before = dict(model.values)
        fr = _fit(model, settings, base=False, free=free, probe=visible)
        if (
            fr.ssr > current.fit.ssr
            and earlier
            and all(abs(model.values[k] - before[k]) < 1e-3 * model.param(k).scale for k in visible)
        ):
            # Stuck where it started, on top of earlier causes: the step to where the new effect
            # trades off against them can be too long for a local fit. Once more, from further in.
            model.values = {
                **before,
                **{
                    k: min(before[k] + 3.0 * model.param(k).scale, model.param(k).high)
                    for k in visible
                },
            }
            again = _fit(model, settings, base=False, free=free)
            if again.ssr < fr.ssr:
                fr = again
    if fr.ssr > current.fit.ssr:
        # Worse than the model it extends (the fit stalled away from the effect's neutral start):
        # the extended model can always do at least as well with the effect switched off.
        model.values = {**current.model.values, **{k: model.param(k).start for k in own}}
        fr = FitResult(
            dict(model.values),
            list(free),
            {k: current.fit.stderr.get(k, math.nan) for k in free},
            current.fit.ssr,
            current.fit.n,
            fr.nfev,
            fr.simulations,
            "no better than the current model",
        )
    scored = _score(f"{current.label} + {key}", (*current.causes, key), model, fr)
    c = CandidateResult(
        round=rnd,
        effect=key,
        name=eff.name,
        params={k.rpartition(".")[2]: model.values[k] for k in visible},
        stderr={k.rpartition(".")[2]: fr.stderr.get(k, math.nan) for k in visible},
        fixed=fixed,
        heldout_error=scored.heldout,
        gain=0.0,
        gain_vs_base=0.0,
        criterion=scored.bic,
        delta_criterion=0.0,
        significant=False,
        scored=scored,
        quick=quick,
    )
    _judge(c, current, base, settings)
    return c


def _rescale(model: Model, sens: dict[str, float], target: float) -> None:
    """Give each new effect parameter the scale (optimiser unit, finite-difference unit and probe
    unit) whose change moves the residuals by about ``target`` RMS, from its sensitivity per unit
    (:func:`_unit_sensitivity`): effect ranges are generous and say little about the size that
    matters, and a step that is too small only sees the saw-tooth of contact detection."""
    from dataclasses import replace as _replace

    out = []
    for p in model.params:
        s = sens.get(p.key, math.nan)
        if math.isfinite(s) and s > 0 and target > 0:
            span = p.high - p.low
            p = _replace(p, scale=float(min(max(target / s, 1e-5 * span), 0.2 * span)))
        out.append(p)
    model.params = out


def _update(c: CandidateResult, scored: Scored, base: Scored, settings: Settings) -> None:
    """Replace a chosen candidate's fit by a better refit of the same model."""
    m, key = scored.model, c.effect
    c.params = {k: m.values[f"{key}.{k}"] for k in c.params}
    c.stderr = {k: scored.fit.stderr.get(f"{key}.{k}", math.nan) for k in c.params}
    c.heldout_error, c.criterion, c.scored = scored.heldout, scored.bic, scored
    if c.previous is not None:
        _judge(c, c.previous, base, settings)
    c.significant = True


def _judge(c: CandidateResult, current: Scored, base: Scored, settings: Settings) -> None:
    """Set the candidate's gains, ΔBIC and significance against ``current``."""
    c.previous = current
    c.gain = 1.0 - c.heldout_error / current.heldout if current.heldout > 0 else 0.0
    c.gain_vs_base = 1.0 - c.heldout_error / base.heldout if base.heldout > 0 else 0.0
    c.delta_criterion = c.criterion - current.bic
    c.significant = bool(
        c.gain >= settings.min_gain and c.delta_criterion <= -settings.min_delta_bic
    )
    why = []
    if c.gain < settings.min_gain:
        why.append(f"held-out gain {c.gain:+.1%} < {settings.min_gain:.0%}")
    if c.delta_criterion > -settings.min_delta_bic:
        why.append(f"ΔBIC {c.delta_criterion:+.1f} > -{settings.min_delta_bic:g}")
    c.note = "; ".join(why)


def _without(scored: Scored, key: str) -> Model:
    """``scored``'s model without the effect of ``key``, at ``scored``'s other values."""
    m = scored.model
    effects = [e for e in m.effects if str(getattr(e, "key", e.name)) != key]
    params = [p for p in m.params if not (p.kind == "effect" and p.target == key)]
    out = Model(m.problem, effects, params)
    out.values.update({k: v for k, v in m.values.items() if k in out.values})
    return out


def _eliminate(
    current: Scored, causes: list[str], results: list[CandidateResult], settings: Settings
) -> tuple[Scored, list[str]]:
    """Backward check after the greedy additions: drop a cause whose removal (and a refit of the
    rest) costs less than ``min_gain`` of held-out error, e.g. one added first that a later,
    better cause made redundant."""
    changed = True
    while changed and len(causes) > 1:
        changed = False
        for key in list(causes):
            m = _without(current, key)
            free = [k for k in current.fit.free if k in m.values]
            fr = _fit(m, settings, base=False, free=free)
            reduced = _score(current.label, tuple(c for c in causes if c != key), m, fr)
            loss = 1.0 - current.heldout / reduced.heldout if reduced.heldout > 0 else 0.0
            if loss < settings.min_gain:
                for c in results:
                    if c.chosen and c.effect == key:
                        c.chosen = False
                        c.note = (
                            f"added in round {c.round}, then dropped: without it the other causes predict the held-out "
                            f"data within {loss:+.1%}"
                        )
                causes = [c for c in causes if c != key]
                current, changed = reduced, True
                break
    return current, causes


def _refit(current: Scored, other: Model, settings: Settings) -> Scored | None:
    """``current``'s model refitted from ``other``'s values of the parameters they share; the
    refit when it fits better than ``current``, else None."""
    m = current.model.copy()
    m.values.update({k: v for k, v in other.values.items() if k in m.values})
    fr = _fit(m, settings, base=False, free=current.fit.free)
    if fr.ssr >= current.fit.ssr * (1 - 1e-6):
        return None
    return _score(current.label, current.causes, m, fr)


def renderer_for(runs: Sequence[Run], mode: str | None = None) -> Renderer:
    """The raster renderer whose output matches the runs' frames ``(T, C, H, W)``: width ``W``;
    mode ``mask`` for one channel, ``mark`` for two, ``instance`` for one per body."""
    from physbench.render.raster import RasterRenderer

    f = runs[0].frames
    assert f is not None
    _, c, h, w = f.shape
    n = len(runs[0].scene.bodies)
    if mode is None:
        mode = {1: "mask", 2: "mark"}.get(c, "instance" if c == n else "")
        if not mode:
            raise DiscoverError(
                f"frames have {c} channels; the raster renderer gives 1 (mask), 2 (mark) or {n} (instance, one per body)"
            )
    r = RasterRenderer(resolution=int(w), mode=mode)  # square pixels: the height follows the world
    exp = r.shape(runs[0].scene)
    if exp[1:] != (c, h, w):
        raise DiscoverError(
            f"frames have (C, H, W) = {(c, h, w)} but the raster renderer in {mode!r} mode gives {exp[1:]}"
        )
    return r
