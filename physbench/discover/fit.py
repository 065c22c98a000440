"""Fitting a model's free parameters to the data: a bounded local least-squares fit on the residual
vector (trust-region reflective, finite-difference Jacobian), optionally started from the best point
of any registered black-box estimator (ask/tell, as in the correction loop).

Uncertainty: the result's ``stderr`` is the i.i.d. Jacobian standard error ``s² (JᵀJ)⁻¹`` with
``s² = SSR / (n - p)``, a lower bound when residuals are correlated in time; its ``intervals``
are 90 % intervals that allow for that correlation (:mod:`physbench.discover.intervals`).

:func:`fit_model` is the fit every stage uses, with the budgets, horizons and estimator of the
:class:`~physbench.discover.settings.Settings`; :func:`score` scores a fitted model on the held-out
data. The fits set the model's values to the optimum in place.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from physbench.discover.data import DiscoverError, Run
from physbench.discover.intervals import METHOD, ar1_covariance
from physbench.discover.model import FitParameter, Model
from physbench.discover.residuals import rms
from physbench.discover.results import FitResult, Scored
from physbench.discover.settings import Settings
from physbench.errors import SimulationError

#: Residual given to every entry of a simulation that explodes, in units of the start's RMS.
FAILED_RESIDUAL = 100.0
#: How many times a fit that ends at the end of an extensible effect range widens it (x10) and
#: refits from there: the declared ranges are typical sizes, not limits of the scene at hand.
WIDENINGS = 3
#: How close to an end of its range (in units of the range's width) a value counts as at it.
BOUND_TOL = 1e-3


def _vector(model: Model, keys: Sequence[str]) -> tuple[np.ndarray, list[FitParameter]]:
    ps = [model.param(k) for k in keys]
    return np.array([model.values[k] for k in keys], dtype=float), ps


def least_squares(
    model: Model,
    free: Sequence[str],
    *,
    role: str = "fit",
    runs: Sequence[int] | None = None,
    max_nfev: int = 40,
    budget: int | None = None,
    diff_step: float = 0.3,
    tol: float = 1e-8,
    horizons: Sequence[float] = (1.0,),
    final: bool = True,
    uncertainty: bool = True,
) -> FitResult:
    """Fit ``free`` (keys) of ``model`` to the parts of ``role``, starting from ``model.values``;
    the model's values are set to the optimum. ``diff_step`` is the finite-difference step in units
    of each parameter's scale (:attr:`FitParameter.scale`). ``budget`` caps the simulations of each
    horizon (the best point so far is kept). ``horizons``: fit the first shares of time in turn,
    each from the last optimum (continuation: a late bounce cannot pull an early fit into a wrong
    valley); unless ``final`` is False, the last horizon is 1 whatever ``horizons`` ends with.
    ``uncertainty``: estimate standard errors and intervals at the optimum (a full fit; a
    profile's inner refit does not need them).

    An effect parameter that ends at the end of an extensible range has its range widened and the
    last horizon refitted from there, up to :data:`WIDENINGS` times; the ones still at a nonzero
    end are listed in the result's ``at_bound``."""
    sims0 = model.problem.simulations
    steps = [h for h in horizons if 0 < h < 1] + ([1.0] if final else [])
    for h in steps[:-1]:
        _lsq(model, free, role, runs, max_nfev, budget, diff_step, tol, h, covariance_needed=False)

    def last() -> FitResult:
        return _lsq(
            model,
            free,
            role,
            runs,
            max_nfev,
            budget,
            diff_step,
            tol,
            steps[-1],
            covariance_needed=final and uncertainty,
        )

    fr = last()
    for _ in range(WIDENINGS):
        ends = [k for k in at_bound(model, free) if model.param(k).extensible]
        if not ends:
            break
        for k in ends:
            model.widen(k)
        fr = last()
    return replace(
        fr,
        simulations=model.problem.simulations - sims0,
        at_bound=tuple(at_bound(model, free)),
    )


def at_bound(model: Model, keys: Sequence[str]) -> list[str]:
    """The effect parameters among ``keys`` whose value is at a nonzero end of its range (within
    :data:`BOUND_TOL` of its width): the data may want a value beyond it. A zero end is where
    an effect switches off, not a limit."""
    out = []
    for k in keys:
        p = model.param(k)
        if p.kind != "effect":
            continue
        v, tol = model.values[k], BOUND_TOL * (p.high - p.low)
        if (p.high != 0 and v >= p.high - tol) or (p.low != 0 and v <= p.low + tol):
            out.append(k)
    return out


class _OutOfBudget(Exception):
    """Raised inside the objective when a fit has used its simulations."""


def _lsq(
    model: Model,
    free: Sequence[str],
    role: str,
    runs: Sequence[int] | None,
    max_nfev: int,
    budget: int | None,
    diff_step: float,
    tol: float,
    horizon: float,
    *,
    covariance_needed: bool = True,
) -> FitResult:
    """One bounded least-squares fit of ``free`` over the first ``horizon`` of time: the best point
    seen is kept (also when ``budget`` runs out), set on the model and, if ``covariance_needed``,
    given its uncertainty."""
    sims0 = model.problem.simulations
    start = _start(model, free, role, runs, horizon)
    if not free or start.r0.size == 0:
        return FitResult(
            dict(model.values),
            list(free),
            {},
            float(start.r0 @ start.r0),
            start.r0.size,
            1,
            model.problem.simulations - sims0,
            "nothing to fit",
        )
    limit = math.inf if budget is None else sims0 + budget
    objective = _Objective(model, free, role, runs, horizon, start, diff_step, limit)
    status, nfev, j = _minimize(objective, max_nfev, tol, budget)
    ssr, z = objective.best
    x = start.point(z)
    values = dict(model.values)
    values.update(zip(free, x.tolist(), strict=True))
    model.values = values
    u = _uncertainty(objective, z, x, ssr, j) if covariance_needed else _Uncertainty()
    return FitResult(
        values,
        list(free),
        u.stderr,
        ssr,
        objective.n,
        nfev,
        model.problem.simulations - sims0,
        status,
        u.corr,
        intervals=u.intervals,
        interval_method=METHOD if u.intervals else "",
        half_widths=u.half_widths,
    )


@dataclass(frozen=True)
class _Start:
    """Where a fit starts: the free parameters, their values clipped to their ranges, and the
    residuals there."""

    params: list[FitParameter]
    x0: np.ndarray
    scale: np.ndarray
    low: np.ndarray
    high: np.ndarray
    r0: np.ndarray

    def point(self, z: np.ndarray) -> np.ndarray:
        """The parameter values ``z`` scales away from the start, clipped to their ranges."""
        return np.clip(self.x0 + z * self.scale, self.low, self.high)


def _start(
    model: Model, free: Sequence[str], role: str, runs: Sequence[int] | None, horizon: float
) -> _Start:
    """Clip the model's values of ``free`` to their ranges and simulate the residuals there."""
    x0, ps = _vector(model, free)
    scale = np.array([p.scale for p in ps])
    low = np.array([p.low for p in ps])
    high = np.array([p.high for p in ps])
    x0 = np.clip(x0, low, high)
    try:
        r0 = model.residuals(role, dict(zip(free, x0, strict=True)), runs, horizon)
    except SimulationError as exc:
        raise DiscoverError(f"the model's starting point does not simulate: {exc}") from exc
    return _Start(ps, x0, scale, low, high, r0)


@dataclass
class _Objective:
    """The residuals as a function of the step ``z`` from the start, in units of each parameter's
    scale, remembering the best point seen. A simulation that fails or changes the number of
    residuals scores :data:`FAILED_RESIDUAL`; reaching ``limit`` simulations stops the fit."""

    model: Model
    free: Sequence[str]
    role: str
    runs: Sequence[int] | None
    horizon: float
    start: _Start
    diff_step: float
    limit: float
    n: int = field(init=False)
    bad: float = field(init=False)
    best: tuple[float, np.ndarray] = field(init=False)  # (SSR, z)
    lo_z: np.ndarray = field(init=False)
    hi_z: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        s, r0 = self.start, self.start.r0
        self.n = r0.size
        self.bad = FAILED_RESIDUAL * max(float(np.sqrt(np.mean(r0 * r0))), 1e-9)
        self.best = (float(r0 @ r0), np.zeros(len(self.free)))
        lo_z, hi_z = (s.low - s.x0) / s.scale, (s.high - s.x0) / s.scale
        # least_squares needs a start strictly inside the bounds it is given.
        self.lo_z = np.where(lo_z >= 0, -1e-12, lo_z)
        self.hi_z = np.where(hi_z <= 0, 1e-12, hi_z)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        if self.model.problem.simulations >= self.limit:
            raise _OutOfBudget
        x = self.start.point(z)
        try:
            r = self.model.residuals(
                self.role, dict(zip(self.free, x, strict=True)), self.runs, self.horizon
            )
        except SimulationError:
            return np.full(self.n, self.bad)
        if r.size != self.n:
            return np.full(self.n, self.bad)
        s = float(r @ r)
        if s < self.best[0]:
            self.best = (s, z.copy())
        return r

    def jac(self, z: np.ndarray) -> np.ndarray:
        """Forward differences with a fixed step in scaled units (scipy's relative step vanishes
        at z = 0, where every fit starts), stepping backwards at an upper bound."""
        f0 = self(z)
        out = np.empty((self.n, z.size))
        for i in range(z.size):
            h = self.diff_step if z[i] + self.diff_step <= self.hi_z[i] else -self.diff_step
            zi = z.copy()
            zi[i] += h
            out[:, i] = (self(zi) - f0) / h
        return out


def _minimize(
    objective: _Objective, max_nfev: int, tol: float, budget: int | None
) -> tuple[str, int, np.ndarray | None]:
    """Run scipy's bounded least squares from z = 0; returns its status, its evaluations and its
    Jacobian at the optimum (None when the best point is not scipy's own)."""
    from scipy.optimize import least_squares as lsq

    status, nfev, j = "", 0, None
    try:
        res = lsq(
            objective,
            np.zeros(len(objective.free)),
            jac=objective.jac,
            bounds=(objective.lo_z, objective.hi_z),
            method="dogbox",
            x_scale=1.0,
            max_nfev=max_nfev,
            ftol=tol,
            xtol=tol,
            gtol=tol,
        )
        status, nfev = str(res.message), int(res.nfev)
        if float(res.fun @ res.fun) <= objective.best[0]:
            objective.best, j = (float(res.fun @ res.fun), res.x), res.jac
    except _OutOfBudget:
        status = f"stopped after {budget} simulations (best point kept)"
    return status, nfev, j


@dataclass
class _Uncertainty:
    """Standard errors, correlations and 90 % intervals (with their unclipped half widths) of the
    fitted parameters; empty when not asked for."""

    stderr: dict[str, float] = field(default_factory=dict)
    corr: dict[str, dict[str, float]] = field(default_factory=dict)
    intervals: dict[str, tuple[float, float]] = field(default_factory=dict)
    half_widths: dict[str, float] = field(default_factory=dict)


def _uncertainty(
    objective: _Objective, z: np.ndarray, x: np.ndarray, ssr: float, j: np.ndarray | None
) -> _Uncertainty:
    """The uncertainty at the optimum ``z`` (values ``x``) from the fit's Jacobian ``j``, or a
    fresh one; these simulations are not held to the fit's budget."""
    objective.limit = math.inf
    if j is None:
        j = objective.jac(z)
    free, scale, ps = objective.free, objective.start.scale, objective.start.params
    stderr, corr = covariance(j, ssr, objective.n, scale, free)
    r = objective(z)
    ar1 = ar1_covariance(j, r, objective.model.problem.series(objective.role, objective.runs))
    hw = ar1.half_width() * scale
    return _Uncertainty(
        stderr,
        corr,
        intervals={
            k: (max(float(x[i] - hw[i]), ps[i].low), min(float(x[i] + hw[i]), ps[i].high))
            for i, k in enumerate(free)
        },
        half_widths={k: float(hw[i]) for i, k in enumerate(free)},
    )


def probe_start(
    model: Model,
    keys: Sequence[str],
    *,
    role: str = "fit",
    multiples: Sequence[float] = (2.5, 10.0, 25.0),
) -> float:
    """Move ``keys`` to the best of a few probe points before a local fit: each key alone at its
    current value ± ``multiples`` of its scale (:attr:`FitParameter.scale`), then all keys at their
    best probes together. Local least squares on contact-rich scenes stalls in the nearest valley; a
    handful of probes finds a better one cheaply. Returns the SSR at the chosen start (the model's
    values are set to it)."""

    def ssr(vals: dict[str, float]) -> float:
        try:
            r = model.residuals(role, vals)
        except SimulationError:
            return math.inf
        return float(r @ r)

    best = ssr({})
    moves: dict[str, float] = {}
    for k in keys:
        p = model.param(k)
        v0, best_k = model.values[k], best
        for f in multiples:
            for sign in (1.0, -1.0):
                v = v0 + sign * f * p.scale
                if not p.low <= v <= p.high:
                    continue
                s = ssr({k: v})
                if s < best_k:
                    best_k, moves[k] = s, v
    if not moves:
        return best
    singles = {k: ssr({k: v}) for k, v in moves.items()}
    choice, value = min(singles.items(), key=lambda kv: kv[1]), None
    candidates = [({choice[0]: moves[choice[0]]}, choice[1])]
    if len(moves) > 1:
        candidates.append((dict(moves), ssr(dict(moves))))
    vals, value = min(candidates, key=lambda c: c[1])
    if value < best:
        model.values.update(vals)
        return value
    return best


def covariance(
    jac: np.ndarray, ssr: float, n: int, scale: np.ndarray, keys: Sequence[str]
) -> tuple[dict[str, float], dict[str, dict[str, float]]]:
    """Standard errors and correlations from the Jacobian (in scaled units) at the optimum."""
    p = len(keys)
    if p == 0:
        return {}, {}
    dof = max(n - p, 1)
    s2 = ssr / dof
    jtj = np.asarray(jac, dtype=float).T @ np.asarray(jac, dtype=float)
    cov = np.linalg.pinv(jtj, rcond=1e-12) * s2
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    stderr = {k: float(sd[i] * scale[i]) for i, k in enumerate(keys)}
    with np.errstate(invalid="ignore", divide="ignore"):
        c = cov / np.outer(sd, sd)
    corr = {
        k: {q: float(c[i, j]) for j, q in enumerate(keys) if j != i and np.isfinite(c[i, j])}
        for i, k in enumerate(keys)
    }
    return stderr, corr


def estimator_fit(
    model: Model,
    free: Sequence[str],
    estimator: str,
    *,
    iterations: int = 60,
    seed: int = 0,
    options: dict[str, object] | None = None,
) -> dict[str, float]:
    """Search ``free`` with a registered black-box estimator (``tpe``, ``cmaes``, ``optuna``,
    ``random``, ...), one simulation per iteration, on the mean squared residual of the fit part;
    returns the best values found (the model's values are set to them)."""
    from physbench.components import create
    from physbench.estimators.base import Task
    from physbench.loop import Evaluation, drive
    from physbench.unknowns import ParamSpace

    est = create("estimator", estimator, options)
    if type(est).per_object:
        raise DiscoverError(
            f"estimator {estimator!r} corrects marked objects in images; discovery needs a "
            "black-box estimator (tpe, cmaes, optuna, random) or 'lsq'"
        )
    if isinstance(iterations, bool) or not isinstance(iterations, int) or iterations < 1:
        raise DiscoverError(f"estimator iterations = {iterations!r}: expected a whole number >= 1")
    ps = [model.param(k) for k in free]
    space = ParamSpace(tuple(ps))
    current = {k: min(max(model.values[k], p.low), p.high) for k, p in zip(free, ps, strict=True)}
    r0 = model.residuals("fit", current)
    worst = FAILED_RESIDUAL**2 * max(float(np.mean(r0 * r0)), 1e-18)
    none = np.zeros((0, 1, 1, 1), np.float32)  # no frames: the loss is on trajectories

    def evaluate(params: dict[str, float]) -> Evaluation:
        try:
            r = model.residuals("fit", params)
            return Evaluation(float(np.mean(r * r)), none)
        except SimulationError as exc:
            return Evaluation(worst, none, failed=str(exc))

    best, best_loss = dict(current), float(np.mean(r0 * r0))

    def visit(k: int, params: dict[str, float], ev: Evaluation, t_estimator: float) -> None:
        nonlocal best, best_loss
        if ev.loss < best_loss:
            best, best_loss = dict(params), ev.loss

    task = Task(
        scene=model.problem.runs[0].scene,
        space=space,
        observation=none,
        initial=current,
        renderer=None,
        iterations=iterations,
    )
    drive(est, task, evaluate, seed=seed, visit=visit)
    model.values.update(best)
    return best


# --------------------------------------------------------------------------- with the settings


def fit_model(
    model: Model,
    settings: Settings,
    *,
    base: bool,
    free: Sequence[str] | None = None,
    probe: Sequence[str] = (),
    horizons: Sequence[float] | None = None,
) -> FitResult:
    """Fit ``free`` (default :meth:`Model.free_keys`) of ``model`` with the budgets of
    ``settings``: for the ``base`` fit first the black-box estimator of ``settings`` (if any),
    then :func:`probe_start` over ``probe``, least squares over the continuation ``horizons``
    (default :func:`fit_horizons`), and with a runs split each held-out run's own nuisance on its
    lead-in. The model's values are set to the optimum."""
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
        budget=budget(settings, len(keys)) * (2 if base else 1),
        diff_step=settings.diff_step,
        horizons=horizons or fit_horizons(model, settings),
    )
    split = model.problem.split
    for i in split.test_runs if split.kind == "runs" else ():
        own = [p.key for p in model.params if p.kind == "nuisance" and p.run == i]
        if own:
            least_squares(
                model,
                own,
                role="lead",
                runs=[i],
                max_nfev=settings.max_nfev,
                budget=budget(settings, len(own)),
                diff_step=settings.diff_step,
            )
    return fr


def budget(settings: Settings, free: int) -> int:
    """Simulations per fit horizon: ``settings.budget`` for up to 7 free parameters, growing with
    the Jacobian's cost beyond."""
    return int(settings.budget * max(1.0, (free + 1) / 8))


def is_rough(runs: Sequence[Run]) -> bool:
    """Whether the fit landscape is rough: bodies can hit something (static geometry, or each
    other when not jointed), so that impacts detected at discrete steps put a saw-tooth into the
    residuals, or the loss is on images, which stop pulling once shapes no longer overlap."""
    scene = runs[0].scene
    return (
        bool(scene.statics)
        or (len(scene.bodies) > 1 and not scene.joints)
        or any(r.frames is not None for r in runs)
    )


def fit_horizons(model: Model, settings: Settings) -> tuple[float, ...]:
    """The continuation horizons of a fit: ``settings.horizons`` (ending at 1), else (0.5, 1) in
    rough scenes (:func:`is_rough`) and (1,) in smooth ones."""
    if settings.horizons is not None:
        return (*(h for h in settings.horizons if 0 < h < 1), 1.0)
    return (0.5, 1.0) if is_rough(model.problem.runs) else (1.0,)


def score(label: str, causes: tuple[str, ...], model: Model, fr: FitResult) -> Scored:
    """``model`` at its fitted values, scored on the held-out data (infinite error, with the
    reason, when it does not simulate there)."""
    try:
        r = model.residuals("held")
        with np.errstate(over="ignore", invalid="ignore"):
            held, why = rms(r), ""
    except SimulationError as exc:
        r, held, why = np.zeros(0), math.inf, str(exc) or type(exc).__name__
    if not math.isfinite(held) and not why:  # the message that quotes it names what failed
        why = (
            f"the RMS of its {r.size} held-out residuals is {held}"
            if r.size
            else "no held-out residual"
        )
    return Scored(label, causes, model, fr, held, int(r.size), why)
