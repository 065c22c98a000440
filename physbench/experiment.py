"""One run of the correction loop, fully described by data: what ``physbench run`` executes once
and what the benchmark runner executes for every cell of a sweep.

A :class:`RunConfig` names everything that determines the result (scene, unknowns, estimator and
its options, seed, iteration budget, model and observation engines, renderer and its options,
observation blur and noise, resolution, channel layout), so the same configuration gives the same
:class:`~physbench.loop.History` in any process. The observation is simulated from the seed (random
truth, random initial guess) unless ``observation`` names a frames file; a file written by
``physbench simulate`` (or by a run's ``save_observation``) brings its scene instance, its truth
and the engine that made it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from physbench.components import create, make_estimator, make_observer, make_renderer
from physbench.errors import PhysbenchError, UnknownNameError
from physbench.estimators.base import DEFAULT_ESTIMATOR
from physbench.posterior.predictive import DRAWS as PREDICTIVE_DRAWS
from physbench.render.base import DEFAULT_RENDERER
from physbench.simulators.base import DEFAULT_SIMULATOR

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.estimators.base import CorrectionEstimator
    from physbench.loop import History, Iteration, Restart
    from physbench.observation import Observation
    from physbench.posterior.failure import Reference
    from physbench.render.base import Renderer
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator
    from physbench.unknowns import ParamSpace

#: The scene of a run that names none (and observes no file that carries one).
DEFAULT_SCENE = "three_circles"
#: Estimators whose runs restart from a global design by default (``RunConfig.restart``).
RESTART_BY_DEFAULT: frozenset[str] = frozenset()


@dataclass(frozen=True)
class RunConfig:
    """Settings of one run. ``scene``: a registered scene or a scene TOML (``None``: the scene
    of the ``observation`` file, else :data:`DEFAULT_SCENE`; a scene given with a file that
    carries one must be that scene); ``params``: unknown parameter names
    (``("mass", "elasticity")``); ``bodies``: restrict them to these bodies (``None``: every body
    that has them); ``engine``: the model's simulator (``None``: the one that made the
    ``observation`` file, else the default); ``observe_engine``: the engine that makes the
    observation (``None``: ``engine``);
    ``renderer`` and ``renderer_options``: the renderer of the model and of the observation,
    built with ``resolution`` and ``render_mode`` besides its options; ``blur`` and ``noise``:
    the observation model applied to the observed frames only; ``observer`` and
    ``observer_options``: a camera renderer that films the simulated observation as a video,
    which is then tracked and segmented back into the model renderer's frames (the visual gap;
    ``None``: the model renderer draws the observation); ``video``, ``calibration``,
    ``background``, ``video_start`` and ``video_end``: observe a video file instead (a camera's
    footage, tracked and segmented the same way; no truth then); ``effects``: effects the model
    (and a simulated observation) simulates besides the scene's physics, each
    ``NAME[:KEY=NUMBER,...]`` (:func:`~physbench.components.make_effect`), whose parameters
    ``params`` may name by key (``linear_drag.c``) besides gravity and the camera's
    (:func:`~physbench.unknowns.scene_parameters`); ``allow_gaps``: keep a video's
    tracks where a body was lost for more than the tracker's share of the clip (else that is an
    error); ``transfer``: how the video's pixels encode light (``None``: its tag, else the
    default; :mod:`physbench.video.transfer`); ``capture_fps``: the rate a slow-motion video
    was filmed at (:class:`~physbench.video.reader.VideoReader`)."""

    scene: str | None = DEFAULT_SCENE
    params: tuple[str, ...] = ("mass",)
    estimator: str = DEFAULT_ESTIMATOR
    options: Mapping[str, Any] = field(default_factory=dict)
    seed: int = 0
    iterations: int = 11
    engine: str | None = DEFAULT_SIMULATOR
    observe_engine: str | None = None
    renderer: str = DEFAULT_RENDERER
    renderer_options: Mapping[str, Any] = field(default_factory=dict)
    blur: float = 0.0
    noise: float = 0.0
    resolution: int = 64
    render_mode: str = "mark"
    bodies: tuple[str, ...] | None = None
    observation: str | None = None
    observer: str | None = None
    observer_options: Mapping[str, Any] = field(default_factory=dict)
    video: str | None = None
    calibration: str | None = None
    background: str | None = None
    video_start: float | None = None
    video_end: float | None = None
    effects: tuple[str, ...] = ()
    allow_gaps: bool = False
    transfer: str | None = None
    #: Posterior draws the posterior predictive check simulates after the loop, for an
    #: estimator that returns a posterior (:mod:`physbench.posterior.predictive`; 0: no check).
    predictive_draws: int = PREDICTIVE_DRAWS
    #: Restart from a global design while the fit looks failed (:class:`~physbench.loop.Restart`
    #: at the failure threshold of :mod:`physbench.posterior.failure`; it needs a shipped
    #: reference for the run's row and setting). ``None``: on for the estimators in
    #: :data:`RESTART_BY_DEFAULT`.
    restart: bool | None = None
    capture_fps: float | None = None

    def __post_init__(self) -> None:
        """Refuse a numeric setting outside its range (:mod:`physbench.numeric`), NaN and the
        infinities included, naming it."""
        from physbench import numeric

        checks = {
            "seed": numeric.SEED,
            "iterations": numeric.COUNT,
            "blur": numeric.BLUR,
            "noise": numeric.NOISE,
            "resolution": numeric.RESOLUTION,
            "predictive_draws": numeric.COUNT_OR_NONE,
        }
        for name, number in checks.items():
            number.check(getattr(self, name), f"run setting {name}")
        for name in ("video_start", "video_end"):
            if getattr(self, name) is not None:
                numeric.SECONDS.check(getattr(self, name), f"run setting {name}")
        if self.capture_fps is not None:
            numeric.POSITIVE.check(self.capture_fps, "run setting capture_fps")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready settings (tuples as lists); :meth:`from_dict` inverts it. Settings added
        after a sweep format existed are left out while at their defaults, so the cell keys of
        earlier sweeps (hashes of this dict) stay valid."""
        d = asdict(self)
        d["params"] = list(self.params)
        d["effects"] = list(self.effects)
        d["bodies"] = None if self.bodies is None else list(self.bodies)
        d["options"] = dict(self.options)
        d["renderer_options"] = dict(self.renderer_options)
        d["observer_options"] = dict(self.observer_options)
        for key in _LATER:
            if not d[key]:
                del d[key]
        for key, default in _LATER_DEFAULTS.items():
            if d[key] == default:
                del d[key]
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RunConfig:
        """Settings from :meth:`to_dict`; keys written by older versions that lack a setting
        (e.g. ``renderer``) take its default."""
        known = {f.name for f in fields(cls)}
        extra = sorted(set(d) - known)
        if extra:
            raise PhysbenchError(f"run settings: unknown keys {extra}; known: {sorted(known)}")
        kw = dict(d)
        kw["params"] = tuple(kw.get("params", ("mass",)))
        kw["effects"] = tuple(kw.get("effects", ()))
        if kw.get("bodies") is not None:
            kw["bodies"] = tuple(kw["bodies"])
        return cls(**kw)

    @property
    def observer_engine(self) -> str:
        return self.observe_engine or self.engine or DEFAULT_SIMULATOR


#: Settings added after sweeps were first stored: omitted from :meth:`RunConfig.to_dict` while
#: unset (``None`` or empty).
_LATER = (
    "observer",
    "observer_options",
    "video",
    "calibration",
    "background",
    "video_start",
    "video_end",
    "effects",
    "allow_gaps",
    "transfer",
    "restart",
    "capture_fps",
)
#: Settings added later with a default that is not empty: omitted while at that default.
_LATER_DEFAULTS: dict[str, Any] = {"predictive_draws": PREDICTIVE_DRAWS}


def _check_observation(config: RunConfig) -> None:
    given = {"--observation frames": config.observation, "--video": config.video}
    sources = [k for k, v in given.items() if v]
    if config.observer:
        sources.append("an observer camera")
    if len(sources) > 1:
        raise PhysbenchError(
            f"{' and '.join(sources)}: give one source of the observation (frames, a video, or a "
            "simulation filmed by an observer camera)"
        )
    if (
        sources
        and sources[0] != "an observer camera"
        and (config.observe_engine or config.blur or config.noise)
    ):
        raise PhysbenchError(
            f"--observe-engine, --blur and --noise shape a simulated observation; they cannot "
            f"apply to {sources[0]}"
        )
    video_only = {
        "--calibration": config.calibration,
        "--background": config.background,
        "--start": config.video_start,
        "--end": config.video_end,
        "--allow-gaps": config.allow_gaps or None,
        "--transfer": config.transfer,
        "--capture-fps": config.capture_fps,
    }
    if config.observer_options and not config.observer:
        raise PhysbenchError(
            f"observer options {dict(config.observer_options)} but no observer: name the camera "
            "renderer that films the observation (--observer camera)"
        )
    stray = [k for k, v in video_only.items() if v is not None]
    if stray and not config.video:
        raise PhysbenchError(f"{', '.join(stray)} apply to a --video only; no --video was given")
    if config.transfer is not None:
        from physbench.video.transfer import check_transfer

        check_transfer(config.transfer)
    if (config.video or config.observer) and config.render_mode not in ("mark", "instance", "mask"):
        raise PhysbenchError(
            f"render mode {config.render_mode!r}: frames segmented from a video come as masks "
            "(mark, instance or mask)"
        )


def load_observed(config: RunConfig) -> Observation | None:
    """The ``observation`` file of ``config``, read (``None`` when it names none)."""
    from physbench.observation import load_observation

    return load_observation(config.observation) if config.observation else None


def observed_scene(config: RunConfig, observed: Observation | None = None) -> Scene:
    """The scene instance of a run: the one ``observed`` (a loaded file) carries, which a scene
    named in ``config`` must match by name; else ``config.scene`` at ``config.seed``."""
    from physbench.scenes import resolve_scene

    if observed is None or observed.scene is None:
        return resolve_scene(config.scene or DEFAULT_SCENE, config.seed)
    if config.scene is not None:
        named = resolve_scene(config.scene, config.seed).name
        if named != observed.scene.name:
            given = repr(config.scene) + ("" if named == config.scene else f" (scene {named!r})")
            raise PhysbenchError(
                f"--scene {given} does not match the observation {observed.source}, which shows "
                f"scene {observed.scene.name!r}; leave --scene out to use the file's scene"
            )
    return observed.scene


def model_engine(config: RunConfig, observed: Observation | None = None) -> str:
    """The model's simulator: ``config.engine``, else the engine that made ``observed``, else
    the default."""
    return config.engine or (observed.engine if observed else "") or DEFAULT_SIMULATOR


def config_effects(config: RunConfig) -> list[Effect]:
    """The effects of ``config``, built (:func:`~physbench.components.make_effect`)."""
    from physbench.components import make_effect

    return [make_effect(text) for text in config.effects]


def config_space(
    config: RunConfig, scene: Scene | None = None, effects: Sequence[Effect] | None = None
) -> ParamSpace:
    """The unknowns of ``config`` on its scene instance (``scene`` saves regenerating it): the
    scene's body unknowns it names and the scene-level parameters it names by key (gravity, the
    camera's, ``effects``' parameters; ``None``: ``config``'s effects, built). An effect whose
    parameter is given a range beyond its declared one accepts that range from then on."""
    from physbench.unknowns import ParamSpace, scene_parameters

    scene = observed_scene(config) if scene is None else scene
    effects = config_effects(config) if effects is None else effects
    space = ParamSpace.from_scene(
        scene,
        list(config.params),
        None if config.bodies is None else list(config.bodies),
        offered=scene_parameters(effects),
    )
    for eff in effects:
        for u in space.unknowns:
            p = eff.declared.get(u.name) if u.owner == eff.key else None
            if p is not None and (u.low < p.low or u.high > p.high):
                eff.widen(u.name, min(u.low, p.low), max(u.high, p.high))
    return space


def check_model(config: RunConfig, space: ParamSpace, estimator: type[CorrectionEstimator]) -> None:
    """Called before a run or a sweep starts: refuse what the run's observation or ``estimator``
    cannot take: scene-level unknowns for a ``per_object`` estimator, effects or camera errors in
    an observation filmed by an observer (it films the scene's physics with its own true
    calibration)."""
    from physbench.loop import check_marked_space

    check_marked_space(estimator, space)
    if config.observer:
        beyond = [k for k in space.scene_keys if k != "gravity"]
        if beyond or config.effects:
            what = ", ".join([*config.effects, *beyond])
            raise PhysbenchError(
                f"an observer camera films the scene's own physics with its true calibration; it "
                f"cannot show {what}: film the effect with `physbench simulate --renderer camera "
                "--effect ...` and give the clip as --video"
            )


def check_size(config: RunConfig, scene: Scene) -> None:
    """Called before a run starts: refuse one whose estimated memory or time this machine cannot
    give (:mod:`physbench.cost`). It simulates the observation, one probe per unknown and
    direction, and ``iterations`` models, holding three rendered sequences (the observation, the
    model's and the best so far)."""
    from physbench import cost

    n = config.iterations + 1 + 2 * max(1, len(config.params))
    one = cost.of_scene(scene, resolution=config.resolution, mode=config.render_mode, held=3)
    cost.check(
        one.times(n),
        f"this run ({cost.simulations(n, scene, config.resolution)})",
        "the iterations, the resolution or the scene's frames, substeps or bodies",
    )


def check_config(config: RunConfig) -> ParamSpace:
    """Fail fast, before anything runs: every name is registered, the options are accepted, the
    unknowns exist on the scene, the run fits this machine (:func:`check_size`). Returns the
    unknowns."""
    from physbench.plugins import get_registry

    _check_observation(config)
    draws = config.predictive_draws
    if isinstance(draws, bool) or not isinstance(draws, int) or draws == 1 or draws < 0:
        raise PhysbenchError(
            f"predictive draws = {draws!r}: expected 0 (no posterior predictive check) or a "
            "whole number >= 2"
        )
    observed = load_observed(config)
    reg = get_registry()
    try:
        for engine in {model_engine(config, observed), config.observer_engine}:
            reg.get("simulator", engine)
    except UnknownNameError as exc:
        raise PhysbenchError(str(exc)) from None
    estimator = make_estimator(config.estimator, config.options)
    if config.observer:
        make_observer(config.observer, config.observer_options)
    make_renderer(
        config.renderer,
        config.renderer_options,
        resolution=config.resolution,
        mode=config.render_mode,
    )
    scene = observed_scene(config, observed)
    check_size(config, scene)
    space = config_space(config, scene)
    check_model(config, space, type(estimator))
    return space


def model_renderer(config: RunConfig) -> Renderer:
    """The renderer of ``config`` (its options, resolution and channel layout): the model's, and
    the observation's unless a camera films it."""
    return make_renderer(
        config.renderer,
        config.renderer_options,
        resolution=config.resolution,
        mode=config.render_mode,
    )


def make_observation(
    config: RunConfig,
    scene: Scene,
    truth: Mapping[str, float],
    marked: tuple[str, ...],
    renderer: Renderer,
    effects: Sequence[Effect] = (),
) -> Observation:
    """The observation ``config`` asks for, with each ``marked`` body's view: a ``video`` tracked
    and segmented into ``renderer``'s frames, a simulation of ``truth`` filmed by an ``observer``
    camera and segmented the same way, or a simulation (with ``effects``, seen by the camera of
    ``truth``) rendered sharp and degraded by the sensor model (``blur``, ``noise``). (A frames
    file is loaded by :func:`load_observed` instead.)"""
    if config.video:
        from physbench.video.footage import video_observation

        return video_observation(
            config.video,
            scene,
            renderer,
            calibration=config.calibration,
            background=config.background,
            start=config.video_start,
            end=config.video_end,
            marked=marked,
            allow_gaps=config.allow_gaps,
            transfer=config.transfer,
            capture_fps=config.capture_fps,
        )
    simulator = create("simulator", config.observer_engine)
    if config.observer:
        from physbench.video.footage import filmed_observation

        camera = make_observer(config.observer, config.observer_options)
        return filmed_observation(scene, truth, simulator, camera, renderer, marked=marked)
    from physbench.observation import simulate_observation
    from physbench.render.sensor import SensorModel

    sensor = SensorModel(blur=config.blur, noise=config.noise, seed=config.seed)
    return simulate_observation(
        scene,
        truth,
        simulator,
        model_renderer(config),
        marked=marked,
        effects=effects,
        sensor=sensor,
    )


def _probe(
    scene: Scene,
    space: ParamSpace,
    simulator: Simulator,
    renderer: Renderer,
    initial: Mapping[str, float],
    notice: Callable[[str], None] | None,
    effects: Sequence[Effect] = (),
) -> tuple[str, ...]:
    """The unknowns that move no pixel around ``initial`` (one sentence about them to
    ``notice``)."""
    from physbench.posterior import identifiability

    probes = identifiability.probe(
        scene, space, simulator, renderer, dict(initial), effects=effects
    )
    sentence = identifiability.describe(probes)
    if sentence and notice is not None:
        notice(sentence)
    return identifiability.unseen(probes)


def _record_settings(history: History, config: RunConfig, observed: Observation | None) -> None:
    """Write the observation's settings into ``history.meta``: the engine that made it (``None``
    for a video, a file's own maker where it says), the renderer, blur, noise, resolution and
    layout, and the observer, video or simulated effects where there were some."""
    observe_engine: str | None = config.observer_engine
    if observed is not None:
        observe_engine = observed.engine or None
    elif config.video:
        observe_engine = None
    history.meta.update(
        observe_engine=observe_engine,
        renderer=config.renderer,
        renderer_options=dict(config.renderer_options),
        blur=config.blur,
        noise=config.noise,
        resolution=config.resolution,
        render_mode=config.render_mode,
    )
    if config.observer:
        history.meta.update(
            observer=config.observer, observer_options=dict(config.observer_options)
        )
    if config.video:
        history.meta.update(video=config.video, calibration=config.calibration)
    if config.effects:
        history.meta.update(effects=list(config.effects))
    if observed is not None and observed.effects:
        history.meta.update(observe_effects=list(observed.effects))


def _reference(config: RunConfig, observed: Observation | None, scene: Scene) -> Reference | None:
    """What the run's estimator reaches on other seeds of this row in this setting
    (:func:`physbench.posterior.failure.reference`): only for a simulated observation of every
    body's unknowns, with the estimator's default weights."""
    from physbench.posterior import failure

    if observed is not None or config.video or config.observer or config.bodies is not None:
        return None
    if config.effects:
        return None
    if config.options.get("weights"):
        return None
    setting = {
        "engine": model_engine(config),
        "observe_engine": config.observer_engine,
        "renderer": config.renderer,
        "renderer_options": dict(config.renderer_options),
        "resolution": config.resolution,
        "render_mode": config.render_mode,
        "blur": config.blur,
        "noise": config.noise,
    }
    params, iterations = config.params, config.iterations
    return failure.reference(config.estimator, scene.name, params, iterations, setting)


def _restart(config: RunConfig, reference: Reference | None) -> Restart | None:
    """The restart rule of ``config``: at the failure threshold of the row's reference."""
    from physbench.loop import Restart
    from physbench.posterior.failure import SCENE_FACTOR

    wanted = (
        config.restart if config.restart is not None else config.estimator in RESTART_BY_DEFAULT
    )
    if not wanted or reference is None:
        return None
    return Restart(threshold=SCENE_FACTOR * reference.median)


def _with_known_truth(
    observed: Observation, space: ParamSpace, notice: Callable[[str], None] | None
) -> Observation:
    """``observed`` (a file) with the truth of every unknown it knows: its scene's body
    parameters and gravity. A file that cannot say an unknown's truth (an effect's, the camera's)
    has none for the run: ``notice`` says so, and the run reports image MSE only."""
    from dataclasses import replace

    if observed.truth is None or observed.scene is None:
        return observed
    truth = {**observed.truth, "gravity": float(observed.scene.gravity[1])}
    missing = [k for k in space.keys if k not in truth]
    if missing:
        if notice is not None:
            notice(
                f"the observation {observed.source} does not state the true {', '.join(missing)}:"
                " the run reports image MSE only, no normalized error"
            )
        return replace(observed, truth=None)
    return replace(observed, truth=truth)


def run_config(
    config: RunConfig,
    *,
    callback: Callable[[Iteration], None] | None = None,
    save_observation: str | Path | None = None,
    probe: bool = True,
    notice: Callable[[str], None] | None = None,
) -> History:
    """Build the scene, observation, engines, renderers and estimator of ``config`` and run
    :func:`~physbench.loop.refine`. The history's ``meta`` records the observation settings.
    ``callback`` receives each iteration's record; ``save_observation`` writes the frames used.
    ``probe``: first check that every unknown changes the rendered frames
    (:mod:`physbench.posterior.identifiability`; the unseen are in ``History.unseen``, and
    ``notice`` receives one sentence about them before the loop starts). An estimator's
    posterior is then checked against the observation (``config.predictive_draws``
    simulations; :mod:`physbench.posterior.predictive`, in ``History.predictive``)."""
    _check_observation(config)
    from physbench.loop import draw_problem, refine
    from physbench.observation import save_observation as save_obs

    observed = load_observed(config)
    scene = observed_scene(config, observed)
    effects = config_effects(config)
    space = config_space(config, scene, effects)
    check_size(config, scene)
    estimator = make_estimator(config.estimator, config.options)
    check_model(config, space, type(estimator))
    simulator = create("simulator", model_engine(config, observed))
    renderer = model_renderer(config)
    truth, initial = draw_problem(space, config.seed)
    marked = space.bodies if type(estimator).per_object else ()
    obs = (
        _with_known_truth(observed, space, notice)
        if observed is not None
        else make_observation(config, scene, truth, marked, renderer, effects)
    )
    if save_observation:
        save_obs(save_observation, obs)
    unseen = _probe(scene, space, simulator, renderer, initial, notice, effects) if probe else ()
    reference = _reference(config, observed, scene)
    history = refine(
        obs,
        scene,
        space,
        simulator,
        renderer,
        estimator,
        iterations=config.iterations,
        seed=config.seed,
        initial=initial,
        effects=effects,
        callback=callback,
        restart=_restart(config, reference),
    )
    history.unseen = unseen
    if history.fit is not None and reference is not None:
        history.fit = replace(
            history.fit, reference=reference.median, reference_seeds=reference.seeds
        )
    if history.posterior is not None and config.predictive_draws:
        from physbench.posterior import predictive

        history.predictive = predictive.check(
            history.posterior,
            obs.frames,
            scene,
            simulator,
            renderer,
            noise=obs.noise,
            draws=config.predictive_draws,
            seed=config.seed,
            effects=effects,
        )
    _record_settings(history, config, observed)
    return history
