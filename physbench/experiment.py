"""One case of the correction loop, fully described by data: what ``physbench run`` executes once
and what the benchmark runner executes for every cell of a sweep.

A :class:`Case` names everything that determines the result (scene, unknowns, estimator and its
options, seed, iteration budget, model and observation engines, observation blur and noise,
resolution, render mode), so the same case gives the same :class:`~physbench.loop.History` in any
process. The observation is simulated from the seed (random truth, random initial guess) unless
``observation`` names a frames file.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from physbench.errors import PhysbenchError

if TYPE_CHECKING:
    from physbench.loop import History, Record
    from physbench.observation import Observation
    from physbench.params import ParamSpace
    from physbench.scene import Scene


@dataclass(frozen=True)
class Case:
    """Settings of one run. ``params``: unknown parameter names (``("mass", "elasticity")``);
    ``bodies``: restrict them to these bodies (``None``: every body that has them);
    ``observe_engine``: the engine that makes the observation (``None``: ``engine``)."""

    scene: str = "three_circles"
    params: tuple[str, ...] = ("mass",)
    estimator: str = "tpe"
    options: Mapping[str, Any] = field(default_factory=dict)
    seed: int = 0
    iterations: int = 11
    engine: str = "pymunk"
    observe_engine: str | None = None
    blur: float = 0.0
    noise: float = 0.0
    resolution: int = 64
    render_mode: str = "mark"
    bodies: tuple[str, ...] | None = None
    observation: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready settings (tuples as lists); :meth:`from_dict` inverts it."""
        d = asdict(self)
        d["params"] = list(self.params)
        d["bodies"] = None if self.bodies is None else list(self.bodies)
        d["options"] = dict(self.options)
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Case:
        d = dict(d)
        d["params"] = tuple(d.get("params", ("mass",)))
        if d.get("bodies") is not None:
            d["bodies"] = tuple(d["bodies"])
        return cls(**d)

    @property
    def observer_engine(self) -> str:
        return self.observe_engine or self.engine


def make_estimator(name: str, options: Mapping[str, Any]) -> Any:
    """Instantiate the registered estimator ``name``; options it does not take are refused with
    the list of those it does."""
    from physbench.plugins import get_registry

    cls = get_registry().get("estimator", name)
    try:
        return cls(**dict(options))
    except TypeError as exc:
        try:
            accepted = [
                q for q in inspect.signature(cls).parameters if q not in ("self", "args", "kwargs")
            ]
        except (TypeError, ValueError):
            accepted = []
        raise PhysbenchError(
            f"estimator {name!r} does not take options {dict(options)}: {exc}; its options: {', '.join(accepted) or 'none'}"
        ) from None


def case_space(case: Case, scene: Scene | None = None) -> ParamSpace:
    """The unknowns of ``case`` on its scene instance (``scene`` saves regenerating it)."""
    from physbench.params import ParamSpace
    from physbench.scenes import resolve_scene

    scene = resolve_scene(case.scene, case.seed) if scene is None else scene
    return ParamSpace.from_scene(
        scene, list(case.params), None if case.bodies is None else list(case.bodies)
    )


def run_case(
    case: Case,
    *,
    callback: Callable[[Record], None] | None = None,
    save_observation: str | Path | None = None,
) -> History:
    """Build the scene, observation, engines, renderer and estimator of ``case`` and run
    :func:`~physbench.loop.refine`. The history's ``meta`` records the observation settings.
    ``callback`` receives each iteration's record; ``save_observation`` writes the frames used."""
    if case.observation and (case.observe_engine or case.blur or case.noise):
        raise PhysbenchError(
            "--observe-engine, --blur and --noise shape a simulated observation; they cannot apply to --observation frames"
        )
    from physbench.loop import draw_problem, refine
    from physbench.observation import load_observation, simulate_observation
    from physbench.observation import save_observation as save_obs
    from physbench.plugins import create
    from physbench.scenes import resolve_scene

    scene = resolve_scene(case.scene, case.seed)
    space = case_space(case, scene)
    estimator = make_estimator(case.estimator, case.options)
    simulator = create("simulator", case.engine)
    model_renderer = create("renderer", "raster", resolution=case.resolution, mode=case.render_mode)
    per_object = bool(getattr(estimator, "per_object", False))
    truth, initial = draw_problem(space, case.seed)
    obs: Observation
    if case.observation:
        obs = load_observation(case.observation)
    else:
        observer = create("simulator", case.observer_engine)
        obs_renderer = create(
            "renderer",
            "raster",
            resolution=case.resolution,
            mode=case.render_mode,
            blur=case.blur,
            noise=case.noise,
            seed=case.seed,
        )
        obs = simulate_observation(
            scene, truth, observer, obs_renderer, marked=space.bodies if per_object else ()
        )
    if save_observation:
        save_obs(save_observation, obs)
    history = refine(
        obs,
        scene,
        space,
        simulator,
        model_renderer,
        estimator,
        iterations=case.iterations,
        seed=case.seed,
        initial=initial,
        callback=callback,
    )
    history.meta.update(
        observe_engine=None if case.observation else case.observer_engine,
        blur=case.blur,
        noise=case.noise,
        resolution=case.resolution,
        render_mode=case.render_mode,
    )
    return history
