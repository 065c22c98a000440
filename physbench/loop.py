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
from physbench.posterior.samples import Posterior
from physbench.unknowns import Params, ParamSpace

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


def _space(scene: Scene, unknowns: ParamSpace | Sequence[str] | None) -> ParamSpace:
    if isinstance(unknowns, ParamSpace):
        return unknowns
    if isinstance(unknowns, str):
        unknowns = [unknowns]
    return ParamSpace.from_scene(scene, unknowns)


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
) -> History:
    """Run ``iterations`` iterations of the correction loop and return the :class:`History`.

    ``unknowns``: a :class:`ParamSpace`, or parameter names (``["mass"]``) of the scene's unknowns
    (``None``: all of them). ``initial`` defaults to a uniform draw from ``derive_seeds(seed)``; the
    estimator is started with that stream's estimator seed. ``renderer`` is the *model* renderer
    (sharp); an observation model (blur, noise) belongs to whoever made ``observation``.
    ``callback`` is called with each :class:`Iteration` as it completes (progress displays).
    """
    if (
        isinstance(iterations, bool)
        or not isinstance(iterations, int | np.integer)
        or iterations < 1
    ):
        raise PhysbenchError(f"iterations = {iterations!r}: expected a whole number >= 1")
    space = _space(scene, unknowns)
    obs = (
        observation
        if isinstance(observation, Observation)
        else Observation(np.asarray(observation))
    )
    name = type(estimator).name or type(estimator).__name__
    per_object = type(estimator).per_object
    obs = validate(obs, expected_shape(renderer, scene), bodies=space.bodies if per_object else ())
    truth = None
    if obs.truth is not None:
        missing = [k for k in space.keys if k not in obs.truth]
        if missing:
            raise PhysbenchError(
                f"the observation's true parameters {dict(obs.truth)} lack {missing}"
            )
        truth = {k: float(obs.truth[k]) for k in space.keys}

    seeds = derive_seeds(seed)
    if initial is None:
        params = space.sample(seeds.initial)
    else:
        if not set(space.keys) <= set(initial) or not space.contains(initial):
            ranges = ", ".join(f"{u.key} in [{u.low:g}, {u.high:g}]" for u in space.unknowns)
            raise PhysbenchError(
                f"initial guess {dict(initial)}: expected a value for each unknown with {ranges}"
            )
        params = {k: float(initial[k]) for k in space.keys}
    first = dict(params)

    task = Task(
        scene=scene,
        space=space,
        observation=obs.frames,
        initial=dict(first),
        renderer=renderer,
        iterations=int(iterations),
        marked_observation=obs.marked,
        noise=obs.noise,
    )
    t = time.perf_counter()
    with guard("estimator", estimator, "start()"):
        estimator.start(task, seed=seeds.estimator)
    t_start = time.perf_counter() - t

    records: list[Iteration] = []
    best = 0
    for k in range(int(iterations)):
        failed: str | None = None
        traj: Trajectory | None = None
        t0 = time.perf_counter()
        try:
            with guard("simulator", simulator, "simulate()"):
                traj = simulator.simulate(scene, params, effects=effects)
        except SimulationError as exc:
            failed = str(exc)
        t1 = time.perf_counter()
        marked: dict[str, np.ndarray] = {}
        if traj is None:
            frames = np.zeros_like(obs.frames)
            marked = dict.fromkeys(space.bodies, frames) if per_object else {}
            loss = FAILED_LOSS
        else:
            with guard("renderer", renderer, "render()"):
                frames = renderer.render(scene, traj)
                if per_object:
                    marked = {b: renderer.render(scene, traj, focus=b) for b in space.bodies}
            loss = image_mse(frames, obs.frames)
        t2 = time.perf_counter()
        step = Step(k, dict(params), frames, loss, traj, marked=marked)
        with guard("estimator", estimator, "propose()"):
            proposal = estimator.propose(step)
        t3 = time.perf_counter()
        nxt = _check_proposal(name, space, proposal, k)

        nmse = None if truth is None else space.normalized_mse(params, truth)
        if k == 0 or loss < records[best].loss:  # ties keep the earlier iterate
            best = k
        best_loss, best_nmse = (
            (loss, nmse) if best == k else (records[best].loss, records[best].nmse)
        )
        rec = Iteration(
            k,
            dict(params),
            loss,
            nmse,
            best,
            best_loss,
            best_nmse,
            t1 - t0,
            t2 - t1,
            t3 - t2,
            failed,
        )
        records.append(rec)
        if callback is not None:
            callback(rec)
        params = nxt

    with guard("estimator", estimator, "posterior()"):
        posterior = estimator.posterior()
    _check_posterior(name, space, posterior)

    return History(
        iterations=records,
        posterior=posterior,
        keys=space.keys,
        estimator=name,
        at_bound=space.at_bound(records[best].params),
        seed=int(seed),
        initial=first,
        truth=truth,
        options=dict(estimator.options),
        meta={
            "scene": scene.name,
            "simulator": type(simulator).name,
            "per_object": per_object,
            "observation": obs.source,
            "t_start": t_start,
        },
    )
