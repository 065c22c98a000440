"""Observations: the frames the correction loop tries to reproduce, simulated or loaded from a file.

File format (``.npz``, written by :func:`save_observation`, read by :func:`load_observation`):

``frames``
    required, ``(T, C, H, W)`` floats in [0, 1]; ``T`` must equal the scene's frame count and
    ``C, H, W`` the model renderer's output (e.g. the default renderer in ``mark`` mode:
    ``C = 2``, channel 0 every body, channel 1 empty; at ``--resolution 64`` on a square world
    ``H = W = 64``).
``marked_<body>``
    optional, same shape: the frames with ``<body>`` marked (rendered with ``focus=<body>``),
    needed only by estimators that correct one marked object at a time.
``scene_toml``
    optional, a 0-d string: the scene instance observed (:func:`~physbench.scene_toml.dumps_scene`)
    with every body parameter at its true value, so the file carries the truth of any unknowns.
    ``physbench simulate --out`` writes it, and :func:`save_observation` when the truth is known.
``engine``
    optional, a 0-d string: the simulator that made the frames.
``effects``
    optional, strings: the effects simulated besides the scene's physics (``repr`` of each).

A file without ``scene_toml`` (e.g. a camera's frames) carries no truth, so a run on it reports
only image MSE.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError
from physbench.unknowns import scene_values, simulate_seen

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.render.base import Renderer
    from physbench.render.sensor import SensorModel
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator
    from physbench.unknowns import Params

MARK_PREFIX = "marked_"
#: Keys of an observation file besides the frames: scene, engine, effects.
SCENE_KEY, ENGINE_KEY, EFFECTS_KEY = "scene_toml", "engine", "effects"


class ObservationError(PhysbenchError, ValueError):
    """An observation that does not fit the scene or renderer; names expected and got."""


@dataclass
class Observation:
    """Observed frames, the true parameters when known, and per-body marked frames if any.
    ``scene``: the scene instance observed, at the true parameters, when known; ``engine`` and
    ``effects``: what simulated it, when it was simulated (``""`` and ``()`` otherwise)."""

    frames: np.ndarray  # (T, C, H, W) float32 in [0, 1]
    truth: Params | None = None
    marked: dict[str, np.ndarray] = field(default_factory=dict)
    source: str = ""
    scene: Scene | None = None
    engine: str = ""
    effects: tuple[str, ...] = ()
    #: The standard deviation of the observation model's Gaussian pixel noise, when it is known
    #: (a simulated observation); ``None`` for frames from a file or a camera.
    noise: float | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(self.frames.shape)


def expected_shape(renderer: Renderer, scene: Scene) -> tuple[int, int, int, int]:
    """``(T, C, H, W)`` the renderer produces for ``scene`` (:meth:`Renderer.shape`)."""
    return tuple(int(v) for v in renderer.shape(scene))  # type: ignore[return-value]


def check_frames(
    frames: object, expected: Sequence[int], *, what: str = "observation"
) -> np.ndarray:
    """``frames`` as float32 ``(T, C, H, W)``, or :class:`ObservationError` naming expected vs
    got."""
    arr = np.asarray(frames)
    exp = tuple(int(v) for v in expected)
    if arr.shape != exp:
        names = "(T, C, H, W)"
        detail = ""
        if arr.ndim == 4:
            diffs = [
                f"{n} {g} != {e}" for n, g, e in zip("TCHW", arr.shape, exp, strict=True) if g != e
            ]
            detail = " (" + ", ".join(diffs) + ")"
        raise ObservationError(
            f"{what}: frames have shape {arr.shape}, expected {names} = {exp}{detail}; T is the "
            "scene's "
            "frame count, C, H, W the renderer's channels and image size (check --resolution and "
            "the render mode)"
        )
    return check_values(arr, what=what)


def check_values(frames: np.ndarray, *, what: str = "observation") -> np.ndarray:
    """``frames`` as float32, or :class:`ObservationError` unless they are finite numbers in
    [0, 1]. Called on loading a file and by :func:`check_frames`."""
    if frames.dtype.kind not in "fiub":
        raise ObservationError(
            f"{what}: expected numeric frames (floats in [0, 1]), got dtype {frames.dtype}"
        )
    arr = frames.astype(np.float32, copy=False)
    if not np.isfinite(arr).all():
        raise ObservationError(f"{what}: frames contain NaN or inf; expected values in [0, 1]")
    if arr.size:
        lo, hi = float(arr.min()), float(arr.max())
        if lo < -1e-6 or hi > 1 + 1e-6:
            raise ObservationError(
                f"{what}: frame values span [{lo:g}, {hi:g}], expected values in [0, 1]"
            )
    return arr


def validate(
    obs: Observation, expected: Sequence[int], *, bodies: Iterable[str] = ()
) -> Observation:
    """Check ``obs`` against the model's frame shape; ``bodies`` lists the marked frames
    required."""
    what = obs.source or "observation"
    frames = check_frames(obs.frames, expected, what=what)
    marked = {
        b: check_frames(f, expected, what=f"{what} [{MARK_PREFIX}{b}]")
        for b, f in obs.marked.items()
    }
    missing = [b for b in bodies if b not in marked]
    if missing:
        have = ", ".join(sorted(marked)) or "none"
        raise ObservationError(
            f"{what}: no marked frames for {', '.join(missing)} (have: {have}); an estimator that "
            f"corrects one marked object at a time needs '{MARK_PREFIX}<body>' arrays for every "
            "unknown body"
        )
    return replace(obs, frames=frames, marked=marked)


def simulate_observation(
    scene: Scene,
    truth: Mapping[str, float],
    simulator: Simulator,
    renderer: Renderer,
    *,
    marked: Iterable[str] = (),
    effects: Sequence[Effect] = (),
    sensor: SensorModel | None = None,
) -> Observation:
    """Simulate ``scene`` with the true parameters (body parameters, gravity, ``effects``' and the
    camera's: :func:`~physbench.unknowns.simulate_seen`) and render it (and once per ``marked``
    body with that body in focus); ``sensor`` (blur, noise) degrades every rendered view."""
    seen, traj = simulate_seen(simulator, scene, truth, effects)
    views = {None: renderer.render(seen, traj)}
    views.update({b: renderer.render(seen, traj, focus=b) for b in marked})
    if sensor is not None:
        views = {b: sensor.apply(f) for b, f in views.items()}
    frames = views.pop(None)
    name = type(simulator).name
    return Observation(
        frames,
        dict(truth),
        views,
        source=f"simulated ({name})",
        scene=scene.with_params(scene_values(truth, effects)),
        engine=name,
        effects=tuple(repr(e) for e in effects),
        noise=None if sensor is None else float(sensor.noise),
    )


def true_params(scene: Scene) -> Params:
    """Every body parameter of ``scene`` as ``{"body.param": value}`` (a moment left to the shape
    at its value from the mass): the truth of a scene observed at its own values."""
    from physbench.scene import BODY_PARAMS

    return {
        f"{b.name}.{p}": float(b.inertia() if p == "moment" else getattr(b, p))
        for b in scene.bodies
        for p in BODY_PARAMS
    }


def save_observation(path: str | Path, obs: Observation) -> None:
    """Write ``obs`` in the documented ``.npz`` format; its scene (at the true parameters), engine
    and effects go with the frames when the truth is known."""
    arrays = {"frames": np.asarray(obs.frames, np.float32)}
    arrays.update({MARK_PREFIX + b: np.asarray(f, np.float32) for b, f in obs.marked.items()})
    if obs.truth is not None and obs.scene is not None:
        from physbench.scene_toml import dumps_scene

        arrays[SCENE_KEY] = np.array(dumps_scene(obs.scene))
        arrays[ENGINE_KEY] = np.array(obs.engine)
        arrays[EFFECTS_KEY] = np.array(obs.effects, dtype=str)
    np.savez_compressed(path, **arrays)  # type: ignore[arg-type]


def load_observation(path: str | Path) -> Observation:
    """Read an ``.npz`` observation; shape checks against a scene happen in :func:`validate`."""
    p = Path(path)
    if not p.is_file():
        raise ObservationError(f"observation file {str(p)!r} does not exist")
    try:
        with np.load(p, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except Exception as exc:  # zip, pickle and format errors all mean "not a usable .npz"
        raise ObservationError(f"{p}: cannot read as .npz ({type(exc).__name__}: {exc})") from None
    for k, v in arrays.items():
        if not isinstance(v, np.ndarray):  # numpy hands a member that is not .npy over as bytes
            raise ObservationError(
                f"{p}: member {k!r} is not a .npy array; an observation .npz holds only arrays "
                "(as numpy.savez writes them)"
            )
    if "frames" not in arrays:
        raise ObservationError(
            f"{p}: no 'frames' array (found: {', '.join(sorted(arrays)) or 'none'}); expected key "
            "'frames' "
            "holding (T, C, H, W) floats in [0, 1]"
        )
    frames = arrays.pop("frames")
    if frames.ndim != 4:
        raise ObservationError(
            f"{p}: 'frames' has shape {frames.shape}; expected 4 axes (T, C, H, W)"
        )
    frames = check_values(frames, what=f"{p} ['frames']")
    marked = {
        k[len(MARK_PREFIX) :]: check_values(v, what=f"{p} [{k!r}]")
        for k, v in arrays.items()
        if k.startswith(MARK_PREFIX)
    }
    obs = Observation(frames, None, marked, source=str(p))
    if SCENE_KEY not in arrays:
        return obs  # frames only: no truth
    from physbench.scene_toml import loads_scene

    scene = loads_scene(str(arrays[SCENE_KEY]), source=f"{p} [{SCENE_KEY}]")
    engine = str(arrays[ENGINE_KEY]) if ENGINE_KEY in arrays else ""
    effects = tuple(str(e) for e in np.ravel(arrays.get(EFFECTS_KEY, ())))
    return replace(obs, truth=true_params(scene), scene=scene, engine=engine, effects=effects)
