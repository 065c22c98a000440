"""The correction loop (paper Fig. 1): simulate, render, compare with the observation, propose.

One iteration is exactly one simulation and one
:meth:`~physbench.estimators.base.CorrectionEstimator.propose`
call, for every estimator kind, so an iteration count is a fair cost. Iteration 0 simulates the
initial guess; iteration ``k`` simulates ``p_k`` and ``propose`` returns ``p_{k+1}`` (the last
proposal is made, and timed, but not simulated).

Seeds: everything random in a run derives from one ``numpy.random.SeedSequence(seed)`` through
:func:`derive_seeds` (true parameters, initial guess, estimator seed), so the same seed gives the
same history in any process.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from physbench.errors import PhysbenchError, SimulationError
from physbench.estimators.base import Step, Task
from physbench.metrics import image_mse
from physbench.observation import Observation, expected_shape, validate
from physbench.plugins import guard
from physbench.posterior.failure import FitCheck
from physbench.posterior.predictive import PredictiveCheck
from physbench.posterior.samples import Posterior
from physbench.unknowns import Params, ParamSpace, scene_parameters, simulate_seen

if TYPE_CHECKING:
    import pandas as pd

    from physbench.effects.base import Effect
    from physbench.estimators.base import CorrectionEstimator
    from physbench.render.base import Renderer
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator
    from physbench.trajectory import Trajectory

#: Loss given to the estimator when a simulation fails: the largest image MSE that frames in [0, 1]
#: allow.
FAILED_LOSS = 1.0


class EstimatorError(PhysbenchError):
    """An estimator broke its contract (bad proposal, propose before start, ...)."""


@dataclass(frozen=True)
class Seeds:
    truth: np.random.Generator
    initial: np.random.Generator
    estimator: int


def derive_seeds(seed: int) -> Seeds:
    """The three independent streams of a run, all from ``SeedSequence(seed)``."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise PhysbenchError(f"seed = {seed!r}: expected a whole number >= 0")
    truth, initial, est = np.random.SeedSequence(int(seed)).spawn(3)
    return Seeds(
        np.random.default_rng(truth), np.random.default_rng(initial), int(est.generate_state(1)[0])
    )


def draw_problem(space: ParamSpace, seed: int) -> tuple[Params, Params]:
    """Random true parameters and a random initial guess, uniform in the ranges, for ``seed``."""
    s = derive_seeds(seed)
    return space.sample(s.truth), space.sample(s.initial)


@dataclass(frozen=True)
class Iteration:
    """One iteration. ``nmse``/``best_nmse`` are ``None`` when the truth is unknown; times in s."""

    iteration: int
    params: Params
    loss: float
    nmse: float | None
    best_iteration: int
    best_loss: float
    best_nmse: float | None
    t_simulate: float
    t_render: float
    t_estimator: float
    failed: str | None = None


TIMING_FIELDS = ("t_simulate", "t_render", "t_estimator")


@dataclass
class History:
    """What :func:`refine` returns: one :class:`Iteration` per iteration plus the run's settings.

    JSON written before the renames (``records``, ``min_nmse``) is still read by :meth:`from_dict`.
    """

    iterations: list[Iteration]
    keys: tuple[str, ...]
    estimator: str
    seed: int
    initial: Params
    truth: Params | None = None
    options: dict[str, Any] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)
    #: Unknowns that moved no pixel when probed before the run
    #: (:mod:`physbench.posterior.identifiability`): their estimates are guesses. Empty when not
    #: probed.
    unseen: tuple[str, ...] = ()
    #: Unknowns whose best estimate lies at an end of their range
    #: (:meth:`~physbench.unknowns.ParamSpace.at_bound`): the range, not the data, may hold them.
    at_bound: tuple[str, ...] = ()
    #: How sure the estimator is (:meth:`CorrectionEstimator.posterior`); ``None`` for an
    #: estimator that gives a point only.
    posterior: Posterior | None = None
    #: Whether the model reproduces the observation at the posterior's draws
    #: (:mod:`physbench.posterior.predictive`); ``None`` when not checked (no posterior).
    predictive: PredictiveCheck | None = None
    #: Whether the fit failed: its best image MSE against the noise floor and against what the
    #: estimator reaches on other seeds of the scene (:mod:`physbench.posterior.failure`).
    fit: FitCheck | None = None
    #: The iterations that simulated a point of the restart design instead of the estimator's
    #: proposal (:class:`Restart`).
    restarts: tuple[int, ...] = ()

    def __len__(self) -> int:
        return len(self.iterations)

    @property
    def best(self) -> Iteration:
        """The iterate with the lowest image MSE so far (chosen without looking at the truth)."""
        return self.iterations[self.iterations[-1].best_iteration]

    @property
    def best_nmse(self) -> float | None:
        """The paper's score ("normalized min MSE"): the normalized parameter MSE of the iterate
        with the lowest image MSE, which is not the lowest parameter error of the run."""
        return self.iterations[-1].best_nmse

    @property
    def min_loss(self) -> float:
        return self.iterations[-1].best_loss

    @property
    def initial_nmse(self) -> float | None:
        return self.iterations[0].nmse

    def timings(self) -> dict[str, float]:
        """Mean seconds per iteration for each phase (simulate, render, estimator)."""
        return {
            f[2:]: float(np.mean([getattr(r, f) for r in self.iterations])) for f in TIMING_FIELDS
        }

    def to_dict(self, *, timings: bool = True) -> dict[str, Any]:
        """JSON-ready dict; ``timings=False`` drops everything that varies between identical
        runs."""
        recs = []
        for r in self.iterations:
            d = asdict(r)
            if not timings:
                for f in TIMING_FIELDS:
                    d.pop(f)
            recs.append(d)
        out = {
            "estimator": self.estimator,
            "options": self.options,
            "seed": self.seed,
            "keys": list(self.keys),
            "initial": self.initial,
            "truth": self.truth,
            "best_nmse": self.best_nmse,
            "min_loss": self.min_loss,
            "unseen": list(self.unseen),
            "at_bound": list(self.at_bound),
            "posterior": None if self.posterior is None else self.posterior.to_dict(),
            "predictive": (
                None if self.predictive is None else self.predictive.to_dict(timings=timings)
            ),
            "fit": None if self.fit is None else self.fit.to_dict(),
            "restarts": list(self.restarts),
            "meta": {k: v for k, v in self.meta.items() if timings or not k.startswith("t_")},
            "iterations": recs,
        }
        if timings:
            out["timings"] = self.timings()
        return out

    def to_json(self, **kwargs: Any) -> str:
        return json.dumps(self.to_dict(), **kwargs)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> History:
        raw = d["iterations"] if "iterations" in d else d["records"]
        recs = [Iteration(**{**dict.fromkeys(TIMING_FIELDS, 0.0), **r}) for r in raw]
        return cls(
            iterations=recs,
            keys=tuple(d["keys"]),
            estimator=d["estimator"],
            seed=d["seed"],
            initial=dict(d["initial"]),
            truth=None if d.get("truth") is None else dict(d["truth"]),
            options=dict(d.get("options", {})),
            meta=dict(d.get("meta", {})),
            unseen=tuple(d.get("unseen", ())),
            at_bound=tuple(d.get("at_bound", ())),
            posterior=None if d.get("posterior") is None else Posterior.from_dict(d["posterior"]),
            predictive=(
                None if d.get("predictive") is None else PredictiveCheck.from_dict(d["predictive"])
            ),
            fit=None if d.get("fit") is None else FitCheck.from_dict(d["fit"]),
            restarts=tuple(d.get("restarts", ())),
        )

    def to_frame(self) -> pd.DataFrame:
        """One row per iteration; parameters as one column per key (pandas is imported here)."""
        import pandas as pd

        rows = []
        for r in self.iterations:
            row = {k: v for k, v in asdict(r).items() if k != "params"}
            row.update(r.params)
            rows.append(row)
        return pd.DataFrame(rows).set_index("iteration")


def _check_proposal(name: str, space: ParamSpace, proposal: object, iteration: int) -> Params:
    if not isinstance(proposal, Mapping):
        raise EstimatorError(
            f"estimator {name!r} returned {type(proposal).__name__} from propose() in iteration "
            f"{iteration}; "
            f"expected a dict with keys {list(space.keys)}"
        )
    keys = set(space.keys)
    missing, extra = sorted(keys - set(proposal)), sorted(set(proposal) - keys)
    if missing or extra:
        raise EstimatorError(
            f"estimator {name!r} proposed keys {sorted(proposal)} in iteration {iteration}; "
            "expected exactly "
            f"{list(space.keys)}"
            + (f" (missing {missing})" if missing else "")
            + (f" (extra {extra})" if extra else "")
        )
    out: Params = {}
    for u in space.unknowns:
        v = proposal[u.key]
        try:
            x = float(v)  # type: ignore[arg-type]
            shown = repr(x)
        except (TypeError, ValueError):
            x, shown = math.nan, repr(v)
        tol = 1e-9 * (u.high - u.low)
        if not (math.isfinite(x) and u.low - tol <= x <= u.high + tol):
            raise EstimatorError(
                f"estimator {name!r} proposed {u.key} = {shown} in iteration {iteration}; "
                "expected a finite "
                f"number in [{u.low:g}, {u.high:g}]"
            )
        out[u.key] = min(max(x, u.low), u.high)
    return out


def _check_posterior(name: str, space: ParamSpace, posterior: object) -> None:
    if posterior is None:
        return
    if not isinstance(posterior, Posterior):
        raise EstimatorError(
            f"estimator {name!r}: posterior() returned {type(posterior).__name__}, expected a "
            "physbench.posterior.samples.Posterior or None"
        )
    if posterior.keys != space.keys:
        raise EstimatorError(
            f"estimator {name!r}: posterior over {list(posterior.keys)}, expected the run's "
            f"unknowns {list(space.keys)}"
        )


def _space(
    scene: Scene, unknowns: ParamSpace | Sequence[str] | None, effects: Sequence[Effect]
) -> ParamSpace:
    if isinstance(unknowns, ParamSpace):
        return unknowns
    if isinstance(unknowns, str):
        unknowns = [unknowns]
    return ParamSpace.from_scene(scene, unknowns, offered=scene_parameters(effects))


def check_marked_space(estimator: type[CorrectionEstimator], space: ParamSpace) -> None:
    """Refuse scene-level unknowns (gravity, an effect's or the camera's parameters) for an
    estimator that corrects one marked body at a time (``per_object``): they belong to no body.
    Called by :func:`refine`, and by a run's and a sweep's checks before anything runs."""
    if estimator.per_object and space.scene_keys:
        name = estimator.name or estimator.__name__
        they = "it belongs" if len(space.scene_keys) == 1 else "they belong"
        raise PhysbenchError(
            f"estimator {name!r} corrects one marked body at a time, so it cannot fit "
            f"{', '.join(space.scene_keys)} ({they} to no body); use an estimator that searches "
            "the ranges (tpe, cmaes, optuna, random, smc)"
        )


@dataclass(frozen=True)
class Evaluation:
    """What one simulation of a proposed point gives its estimator: the ``loss`` it minimises,
    the simulated ``frames`` (and ``marked`` views) and ``trajectory`` it may read, why the
    simulation ``failed`` (``None`` when it did not), and the seconds it took."""

    loss: float
    frames: np.ndarray
    trajectory: Trajectory | None = None
    marked: Mapping[str, np.ndarray] = field(default_factory=dict)
    failed: str | None = None
    t_simulate: float = 0.0
    t_render: float = 0.0


@dataclass(frozen=True)
class Driven:
    """What :func:`drive` returns besides what its ``visit`` saw: the seconds ``start`` took and
    the estimator's posterior (``None`` for a point estimator)."""

    t_start: float
    posterior: Posterior | None


def drive(
    estimator: CorrectionEstimator,
    task: Task,
    evaluate: Callable[[Params], Evaluation],
    *,
    seed: int,
    visit: Callable[[int, Params, Evaluation, float], None],
    redirect: Callable[[int, Params], Params] | None = None,
) -> Driven:
    """The one place that calls an estimator: :meth:`~CorrectionEstimator.start` once with
    ``task``, then for each of ``task.iterations`` iterations ``evaluate`` the current point, show
    the estimator the :class:`~physbench.estimators.base.Step` and check its proposal (keys,
    ranges), then :meth:`~CorrectionEstimator.posterior`. Every call is guarded (what a third
    party's component raises names it). ``visit(k, params, evaluation, t_estimator)`` receives
    each iteration once its proposal is checked; ``redirect(k, proposal)``, when given, then
    names the point simulated next (the loop's restarts, :class:`Restart`). The image loop
    (:func:`refine`) and discovery's black-box fits both run through here."""
    name = type(estimator).name or type(estimator).__name__
    t = time.perf_counter()
    with guard("estimator", estimator, "start()"):
        estimator.start(task, seed=seed)
    t_start = time.perf_counter() - t
    params = dict(task.initial)
    for k in range(task.iterations):
        ev = evaluate(params)
        step = Step(k, dict(params), ev.frames, ev.loss, ev.trajectory, marked=dict(ev.marked))
        t = time.perf_counter()
        with guard("estimator", estimator, "propose()"):
            proposal = estimator.propose(step)
        t_estimator = time.perf_counter() - t
        nxt = _check_proposal(name, task.space, proposal, k)
        visit(k, params, ev, t_estimator)
        params = nxt if redirect is None else redirect(k, nxt)
    with guard("estimator", estimator, "posterior()"):
        posterior = estimator.posterior()
    _check_posterior(name, task.space, posterior)
    return Driven(t_start, posterior)


@dataclass(frozen=True)
class Restart:
    """Restart from a global design when the fit looks failed (``refine(restart=...)``).

    From iteration ``after`` on, at most once every ``every`` iterations, while the best image
    MSE so far is above ``threshold``, the loop simulates the next point of a Latin hypercube of
    ``points`` points over the unknowns' ranges (:mod:`physbench.estimators.design`) instead of
    the estimator's proposal. The estimator is shown that point's simulation and goes
    on from there, which suits correctors that propose from the step they are shown (resnet3d);
    a model-based optimiser just sees one more point. The best iterate is still the one with the
    lowest image MSE of the whole run, and ``History.restarts`` lists the iterations that
    simulated a design point."""

    threshold: float
    after: int = 3
    every: int = 3
    points: int = 8

    def __post_init__(self) -> None:
        if not (math.isfinite(self.threshold) and self.threshold > 0):
            raise PhysbenchError(f"restart threshold {self.threshold!r}: expected a number > 0")
        for name in ("after", "every", "points"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise PhysbenchError(f"restart {name} = {v!r}: expected a whole number >= 1")


def _redirect(
    restart: Restart, space: ParamSpace, seed: int, records: list[Iteration], done: list[int]
) -> Callable[[int, Params], Params]:
    """The loop's restart rule (:class:`Restart`) as :func:`drive`'s ``redirect``; appends to
    ``done`` the iterations that will simulate a design point."""
    from physbench.estimators.design import startup_design

    design = startup_design("lhs", restart.points, len(space), np.random.default_rng([seed, 37]))
    used = [0]

    def redirect(k: int, proposal: Params) -> Params:
        last = done[-1] if done else -restart.every
        if (
            k + 1 < restart.after
            or k + 1 - last < restart.every
            or used[0] >= restart.points
            or records[-1].best_loss <= restart.threshold
        ):
            return proposal
        point = space.from_unit(design[used[0]])
        used[0] += 1
        done.append(k + 1)
        return point

    return redirect


def _checked_iterations(iterations: object) -> int:
    if (
        isinstance(iterations, bool)
        or not isinstance(iterations, int | np.integer)
        or iterations < 1
    ):
        raise PhysbenchError(f"iterations = {iterations!r}: expected a whole number >= 1")
    return int(iterations)


def _truth(obs: Observation, space: ParamSpace) -> Params | None:
    """The observation's true values of the unknowns (``None``: it carries none)."""
    if obs.truth is None:
        return None
    missing = [k for k in space.keys if k not in obs.truth]
    if missing:
        raise PhysbenchError(f"the observation's true parameters {dict(obs.truth)} lack {missing}")
    return {k: float(obs.truth[k]) for k in space.keys}


def _first_guess(space: ParamSpace, seed: int, initial: Mapping[str, float] | None) -> Params:
    """``initial`` checked against the ranges, else a uniform draw from the seed's stream."""
    if initial is None:
        return space.sample(derive_seeds(seed).initial)
    if not set(space.keys) <= set(initial) or not space.contains(initial):
        ranges = ", ".join(f"{u.key} in [{u.low:g}, {u.high:g}]" for u in space.unknowns)
        raise PhysbenchError(
            f"initial guess {dict(initial)}: expected a value for each unknown with {ranges}"
        )
    return {k: float(initial[k]) for k in space.keys}


def image_objective(
    obs: Observation,
    scene: Scene,
    space: ParamSpace,
    simulator: Simulator,
    renderer: Renderer,
    *,
    per_object: bool,
    effects: Sequence[Effect] = (),
) -> Callable[[Params], Evaluation]:
    """The loop's objective: simulate a point as the run's camera sees it
    (:func:`~physbench.unknowns.simulate_seen`), render it (and each unknown body marked, for a
    ``per_object`` estimator) and compare with ``obs`` by image MSE. A simulation that fails
    gives empty frames and :data:`FAILED_LOSS`."""

    def evaluate(params: Params) -> Evaluation:
        t0 = time.perf_counter()
        try:
            with guard("simulator", simulator, "simulate()"):
                seen, traj = simulate_seen(simulator, scene, params, effects)
        except SimulationError as exc:
            frames = np.zeros_like(obs.frames)
            marked = dict.fromkeys(space.bodies, frames) if per_object else {}
            t1 = time.perf_counter()
            return Evaluation(FAILED_LOSS, frames, None, marked, str(exc), t1 - t0, 0.0)
        t1 = time.perf_counter()
        with guard("renderer", renderer, "render()"):
            frames = renderer.render(seen, traj)
            marked = (
                {b: renderer.render(seen, traj, focus=b) for b in space.bodies}
                if per_object
                else {}
            )
        loss = image_mse(frames, obs.frames)
        return Evaluation(loss, frames, traj, marked, None, t1 - t0, time.perf_counter() - t1)

    return evaluate


def _fit(obs: Observation, min_loss: float, best: np.ndarray) -> FitCheck:
    """The best image MSE against the pixel noise's own, when the noise level is known: stated
    by the observation model, or estimated from the frames above an 8-bit step (frames without
    noise leave the measure out)."""
    from physbench.posterior.failure import noise_floor
    from physbench.posterior.likelihood import NOISE_FLOOR, estimate_noise

    sigma = obs.noise if obs.noise is not None else estimate_noise(obs.frames)
    if not sigma or sigma <= NOISE_FLOOR:
        return FitCheck(min_loss)
    return FitCheck(min_loss, noise_floor=noise_floor(best, sigma))


def refine(
    observation: Observation | np.ndarray,
    scene: Scene,
    unknowns: ParamSpace | Sequence[str] | None,
    simulator: Simulator,
    renderer: Renderer,
    estimator: CorrectionEstimator,
    *,
    iterations: int,
    seed: int = 0,
    initial: Mapping[str, float] | None = None,
    effects: Sequence[Effect] = (),
    callback: Callable[[Iteration], None] | None = None,
    restart: Restart | None = None,
) -> History:
    """Run ``iterations`` iterations of the correction loop and return the :class:`History`.

    ``unknowns``: a :class:`ParamSpace`, or parameter names (``["mass"]``) of the scene's unknowns
    (``None``: all of them) and keys of scene-level parameters (``"gravity"``, an effect's
    ``"linear_drag.c"``, ``"camera.scale"``; :func:`~physbench.unknowns.scene_parameters`), each
    optionally with a range (``"gravity=-11:-9"``). ``effects``: what the model simulates besides
    the scene's physics. An estimator that is ``per_object`` is refused scene-level unknowns.
    ``initial`` defaults to a uniform draw from ``derive_seeds(seed)``; the estimator is started
    with that stream's estimator seed. ``renderer`` is the *model* renderer
    (sharp); an observation model (blur, noise) belongs to whoever made ``observation``.
    ``callback`` is called with each :class:`Iteration` as it completes (progress displays).
    ``restart``: restart from a global design while the fit looks failed (:class:`Restart`;
    ``None``: never). ``History.fit`` holds the best image MSE against the pixel noise's
    (:mod:`physbench.posterior.failure`).
    """
    iterations = _checked_iterations(iterations)
    space = _space(scene, unknowns, effects)
    check_marked_space(type(estimator), space)
    obs = (
        observation
        if isinstance(observation, Observation)
        else Observation(np.asarray(observation))
    )
    name = type(estimator).name or type(estimator).__name__
    per_object = type(estimator).per_object
    obs = validate(obs, expected_shape(renderer, scene), bodies=space.bodies if per_object else ())
    truth = _truth(obs, space)
    first = _first_guess(space, seed, initial)
    task = Task(
        scene=scene,
        space=space,
        observation=obs.frames,
        initial=dict(first),
        renderer=renderer,
        iterations=iterations,
        marked_observation=obs.marked,
        noise=obs.noise,
    )
    records: list[Iteration] = []
    best_frames: list[np.ndarray] = []

    def visit(k: int, params: Params, ev: Evaluation, t_estimator: float) -> None:
        nmse = None if truth is None else space.normalized_mse(params, truth)
        best = k if k == 0 or ev.loss < records[-1].best_loss else records[-1].best_iteration
        if best == k:
            best_frames[:] = [ev.frames]
        held = records[best] if best < k else None  # ties keep the earlier iterate
        rec = Iteration(
            k,
            dict(params),
            ev.loss,
            nmse,
            best,
            ev.loss if held is None else held.loss,
            nmse if held is None else held.nmse,
            ev.t_simulate,
            ev.t_render,
            t_estimator,
            ev.failed,
        )
        records.append(rec)
        if callback is not None:
            callback(rec)

    evaluate = image_objective(
        obs, scene, space, simulator, renderer, per_object=per_object, effects=effects
    )
    restarts: list[int] = []
    redirect = None if restart is None else _redirect(restart, space, seed, records, restarts)
    est_seed = derive_seeds(seed).estimator
    driven = drive(estimator, task, evaluate, seed=est_seed, visit=visit, redirect=redirect)
    return History(
        iterations=records,
        posterior=driven.posterior,
        restarts=tuple(restarts),
        fit=_fit(obs, records[-1].best_loss, best_frames[0]),
        keys=space.keys,
        estimator=name,
        at_bound=space.at_bound(records[records[-1].best_iteration].params),
        seed=int(seed),
        initial=first,
        truth=truth,
        options=dict(estimator.options),
        meta=_meta(scene, simulator, per_object, obs, driven),
    )


def _meta(
    scene: Scene, simulator: Simulator, per_object: bool, obs: Observation, driven: Driven
) -> dict[str, Any]:
    """What a history records about the run's setting in ``meta``."""
    return {
        "scene": scene.name,
        "simulator": type(simulator).name,
        "per_object": per_object,
        "observation": obs.source,
        "t_start": driven.t_start,
    }
