"""The discovery pipeline as named stages that take and return values; :func:`discover` composes
them::

    base = fit_base(runs, simulator, settings)                # Scored: the base model, fitted
    diagnosis = diagnose(base)                                # what it gets wrong, as numbers
    specs, skipped = candidate_specs(scene, settings)         # which effects to try
    selection = select_causes(base, specs, settings, skipped) # greedy rounds of candidate fits
    selection = prune_causes(selection, settings)             # drop causes made redundant
    selection = compare_explanations(selection, specs, settings)  # what it cannot tell apart
    disc = conclude(selection, settings)                      # Discovery, for the verdict

One candidate can be tried by hand on a fitted model with
:func:`~physbench.discover.trial.try_effect`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from physbench.discover import diagnostics
from physbench.discover.candidates import CandidateSpec, candidates_for
from physbench.discover.data import DiscoverError, Run, make_split
from physbench.discover.equivalence import compare_explanations
from physbench.discover.fit import fit_model, is_rough, score
from physbench.discover.model import Model, Problem, body_params, nuisance_params
from physbench.discover.profile import profiled
from physbench.discover.results import Discovery, Scored, Selection
from physbench.discover.select import prune_causes, select_causes
from physbench.discover.sensitivity import prune_nuisance
from physbench.discover.settings import Settings
from physbench.errors import SimulationError
from physbench.simulators.base import DEFAULT_SIMULATOR

if TYPE_CHECKING:
    from physbench.discover.residuals import Breakdown
    from physbench.discover.results import Finding
    from physbench.render.base import Renderer
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator


def discover(
    runs: Sequence[Run],
    simulator: Simulator | str = DEFAULT_SIMULATOR,
    *,
    settings: Settings | None = None,
    renderer: Renderer | None = None,
    candidates: Sequence[CandidateSpec] | None = None,
    diagnose: bool = True,
    stage: Callable[[str], None] | None = None,
) -> Discovery:
    """Fit the base model to ``runs``, try every candidate effect, and add the significant ones
    greedily. ``candidates`` overrides the automatic choice (:func:`candidate_specs`);
    ``renderer`` the one :func:`renderer_for` picks for frames; ``diagnose=False`` skips the
    residual statistics of the verdict. ``stage`` is called as each step begins, with ``"base
    fit"``, ``"candidate effects"`` and ``"verdict"`` (a progress display)."""
    started = time.perf_counter()
    settings = settings or Settings()
    stage = stage or (lambda name: None)
    stage("base fit")
    base = fit_base(runs, simulator, settings, renderer=renderer)
    if candidates is None:
        specs, skipped = candidate_specs(base.model.problem.runs[0].scene, settings, runs)
    else:
        specs, skipped = list(candidates), []
    stage("candidate effects")
    selection = prune_causes(select_causes(base, specs, settings, skipped), settings)
    selection = compare_explanations(selection, specs, settings)
    stage("verdict")
    return conclude(selection, settings, diagnose=diagnose, started=started)


def problem_for(
    runs: Sequence[Run],
    simulator: Simulator | str,
    settings: Settings,
    renderer: Renderer | None = None,
) -> Problem:
    """The data side of every model: ``runs`` split by ``settings``, the simulator (an instance
    or a registered name) and, for frames, the renderer (default :func:`renderer_for`)."""
    from physbench.components import create

    sim = create("simulator", simulator) if isinstance(simulator, str) else simulator
    runs = list(runs)
    split = make_split(runs, settings.holdout, settings.split, settings.lead)
    _check_unknowns(runs)
    if renderer is None and any(r.frames is not None for r in runs):
        renderer = renderer_for(runs)
    return Problem(runs, split, sim, renderer)


def start_model(problem: Problem, settings: Settings) -> Model:
    """The base model at the scene's values: its unknowns plus every run's nuisance parameters
    (``settings.nuisance``). Raises :class:`DiscoverError` when it does not simulate over the
    recording."""
    runs = problem.runs
    params = body_params(runs[0].scene)
    for i, r in enumerate(runs):
        params += nuisance_params(r, i, "" if len(runs) == 1 else f"{r.name}/", settings.nuisance)
    start = Model(problem, [], params)
    for role in ("fit", "lead", "held"):
        try:
            start.residuals(role)
        except SimulationError as exc:
            raise DiscoverError(
                f"the scene as given does not simulate over the recording ({role} part): {exc}; "
                "check the scene's bounds, initial state and frame rate against the recording"
            ) from exc
    return start


def fit_base(
    runs: Sequence[Run],
    simulator: Simulator | str = DEFAULT_SIMULATOR,
    settings: Settings | None = None,
    *,
    renderer: Renderer | None = None,
) -> Scored:
    """The base model (the scene's unknowns and the nuisance the data can see) fitted to
    ``runs`` and scored on their held-out part. In contact scenes the fit lands in the valley
    nearest to its start; a second schedule of horizons from the scene's start often finds a
    lower one, and the better is kept."""
    settings = settings or Settings()
    problem = problem_for(runs, simulator, settings, renderer)
    model = prune_nuisance(start_model(problem, settings))
    probe = [p.key for p in model.params if p.kind == "body"]
    fr = fit_model(model, settings, base=True, probe=probe)
    if is_rough(problem.runs) and settings.horizons is None:
        other = Model(problem, [], model.params)
        other_fit = fit_model(other, settings, base=True, probe=probe, horizons=(0.35, 0.7, 1.0))
        if other_fit.ssr < fr.ssr:
            model, fr = other, other_fit
    base = score("base", (), model, fr)
    if not math.isfinite(base.heldout):
        raise DiscoverError(
            f"the fitted base model fails on the held-out data ({base.failure}); check the scene "
            "and the recording"
        )
    return base


def candidate_specs(
    scene: Scene, settings: Settings, runs: Sequence[Run] | None = None
) -> tuple[list[CandidateSpec], list[tuple[str, str]]]:
    """The candidate effects for ``scene`` (``settings.effects``, or every registered one that
    applies; none that ``settings.references`` fix) and the ones left out with the reason;
    ``runs``: the data, whose fields and extent decide the camera's candidates (None: as frames,
    positions within the scene's bounds). Raises :class:`DiscoverError` when effects were named
    and none applies."""
    recordings = None
    if runs is not None and all(r.recording is not None for r in runs):
        recordings = [r.recording for r in runs if r.recording is not None]
    specs, skipped = candidates_for(
        scene, settings.effects, recordings=recordings, references=settings.references
    )
    if settings.effects is not None and not specs:
        why = "; ".join(f"{n}: {r}" for n, r in skipped)
        raise DiscoverError(
            f"none of the requested effects applies to scene {scene.name!r} ({why})"
        )
    return specs, skipped


def conclude(
    selection: Selection,
    settings: Settings,
    *,
    diagnose: bool = True,
    started: float | None = None,
) -> Discovery:
    """The :class:`Discovery` of a selection, with the diagnoses of the base and the final model
    (unless ``diagnose`` is False); ``started``: :func:`time.perf_counter` at the start, for the
    time it took."""
    problem = selection.base.model.problem
    found: dict[str, list[Finding]] = {}
    breakdowns: dict[str, Breakdown] = {}
    if diagnose:
        base = diagnostics.diagnose(selection.base)
        final = diagnostics.diagnose(selection.final) if selection.causes else base
        found = {"base": base.findings, "final": final.findings}
        breakdowns = {"base": base.breakdown, "final": final.breakdown}
    return Discovery(
        runs=problem.runs,
        split=problem.split,
        settings=settings,
        engine=type(problem.simulator).name,
        unit=problem.unit,
        base=selection.base,
        final=selection.final,
        candidates=[profiled(c, settings) if c.chosen else c for c in selection.candidates],
        causes=selection.causes,
        gain=selection.gain,
        skipped=selection.skipped,
        alternatives=selection.alternatives,
        ambiguities=selection.ambiguities,
        priors=selection.priors,
        findings=found,
        breakdowns=breakdowns,
        seconds=0.0 if started is None else time.perf_counter() - started,
    )


def renderer_for(
    runs: Sequence[Run],
    name: str | None = None,
    options: dict[str, Any] | None = None,
    *,
    resolution: int | None = None,
    mode: str | None = None,
) -> Renderer:
    """The registered renderer ``name`` (default
    :data:`~physbench.render.base.DEFAULT_RENDERER`, with ``options``) whose output matches the
    runs' frames ``(T, C, H, W)``: width ``resolution`` (default ``W``; the height follows the
    world); ``mode`` by default from the channels, ``mask`` for one, ``mark`` for two,
    ``instance`` for one per body."""
    from physbench.components import make_renderer
    from physbench.render.base import DEFAULT_RENDERER

    f = runs[0].frames
    if f is None:
        raise DiscoverError(f"run {runs[0].name!r} holds tracks, not frames: nothing to render")
    _, c, h, w = f.shape
    n = len(runs[0].scene.bodies)
    name = name or DEFAULT_RENDERER
    if mode is None:
        mode = {1: "mask", 2: "mark"}.get(c, "instance" if c == n else "")
        if not mode:
            raise DiscoverError(
                f"frames have {c} channels; the render modes give 1 (mask), 2 (mark) or {n} "
                "(instance, one per body)"
            )
    r = make_renderer(
        name, options or {}, resolution=int(w) if resolution is None else resolution, mode=mode
    )
    exp = r.shape(runs[0].scene)
    if exp[1:] != (c, h, w):
        raise DiscoverError(
            f"frames have (C, H, W) = {(c, h, w)} but the {name!r} renderer in {mode!r} mode "
            f"gives {exp[1:]}"
        )
    return r


def _check_unknowns(runs: Sequence[Run]) -> None:
    first = [u.key for u in runs[0].scene.unknowns]
    for r in runs[1:]:
        got = [u.key for u in r.scene.unknowns]
        if got != first:
            raise DiscoverError(
                f"run {r.name!r} declares unknowns {got} but run {runs[0].name!r} declares "
                f"{first}; runs share their unknowns"
            )
