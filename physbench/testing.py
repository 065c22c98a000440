"""Conformance suite for correction estimators, for plugin authors and the built-ins alike.

Plain functions (each raises :class:`ConformanceError` saying what is wrong)::

    from physbench.testing import check_estimator
    check_estimator(MyEstimator, step=0.2)          # keyword options go to MyEstimator(...)

or a pytest base class (pytest collects the subclass, not the base)::

    from physbench.testing import EstimatorConformance

    class TestMyEstimator(EstimatorConformance):
        estimator = MyEstimator
        options = {"step": 0.2}
        bad_options = [{"step": -1.0}]              # each must be refused, naming the option

The checks run the real :func:`physbench.loop.refine` on a tiny closed-form task (:func:`toy_task`:
no physics engine, 16x16 frames), so they take well under a second each, apart from the
other-process check, which starts one Python interpreter.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from physbench.effects.base import Effect
from physbench.errors import PhysbenchError
from physbench.estimators.base import CorrectionEstimator, Step, Task
from physbench.loop import EstimatorError, History, draw_problem, refine
from physbench.observation import Observation, simulate_observation
from physbench.params import ParamSpace
from physbench.render.base import Renderer
from physbench.scene import Body, Circle, Scene, body_unknown
from physbench.simulators.base import Simulator
from physbench.trajectory import Trajectory

__all__ = [
    "ConformanceError",
    "EstimatorConformance",
    "ToyRenderer",
    "ToySimulator",
    "check_bad_input",
    "check_deterministic",
    "check_deterministic_in_subprocess",
    "check_estimator",
    "check_protocol",
    "check_respects_ranges",
    "run_toy",
    "toy_task",
]


class ConformanceError(AssertionError):
    """An estimator failed a conformance check; the message says which and why."""


# --------------------------------------------------------------------------- the toy task


def toy_scene(frames: int = 12) -> Scene:
    """A test body and two unknown bodies ``a``, ``b`` with mass and elasticity unknown."""
    bodies = (
        Body("test", Circle(0.3), (0.6, 2.0), mass=5.0),
        Body("a", Circle(0.3), (1.6, 1.0)),
        Body("b", Circle(0.3), (2.4, 1.0)),
    )
    unknowns = tuple(
        body_unknown(n, p, lo, hi)
        for n in ("a", "b")
        for p, lo, hi in (("mass", 1.0, 10.0), ("elasticity", 0.1, 1.0))
    )
    return Scene("toy", bodies, frames=frames, unknowns=unknowns, test_body="test")


class ToySimulator(Simulator):
    """Closed-form stand-in for a physics engine: a body's speed falls with its mass and its hop
    height grows with its elasticity. Deterministic, about 50 µs per call."""

    name: ClassVar[str] = "toy"

    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        scene = scene.with_params(params or {})
        t = np.arange(scene.frames) / scene.fps
        states = np.zeros((scene.frames, len(scene.bodies), 6))
        for i, b in enumerate(scene.bodies):
            speed = 0.0 if b.name == scene.test_body else 8.0 / (b.mass + 2.0)
            hop = 0.0 if b.name == scene.test_body else 1.2 * b.elasticity
            states[:, i, 0] = b.position[0] + speed * t
            states[:, i, 1] = b.position[1] + hop * np.sin(np.pi * t / max(t[-1], 1e-9))
            states[:, i, 3] = speed
        return Trajectory(scene.body_names, t, states, engine=self.name)


class ToyRenderer(Renderer):
    """Gaussian blobs on a square image of ``resolution`` pixels; channel 1 holds the ``focus``
    body (the ``mark`` layout, its only mode)."""

    name: ClassVar[str] = "toy"
    modes: ClassVar[tuple[str, ...]] = ("mark",)

    def __init__(self, resolution: int = 16, mode: str = "mark") -> None:
        super().__init__(resolution, mode)
        self.size = int(self.resolution)  # type: ignore[arg-type]

    def shape(self, scene: Scene, frames: int | None = None) -> tuple[int, int, int, int]:
        return (scene.frames if frames is None else frames, 2, self.size, self.size)

    def render(
        self,
        scene: Scene,
        traj: Trajectory,
        *,
        focus: str | None = None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        xmin, ymin, xmax, ymax = scene.bounds
        c = (np.arange(self.size) + 0.5) / self.size
        gx, gy = xmin + c * (xmax - xmin), ymax - c * (ymax - ymin)
        frames = np.zeros((traj.frames, 2, self.size, self.size), np.float32)
        for i, name in enumerate(traj.bodies):
            x, y = traj.states[:, i, 0], traj.states[:, i, 1]
            blob = np.exp(
                -(
                    (gy[None, :, None] - y[:, None, None]) ** 2
                    + (gx[None, None, :] - x[:, None, None]) ** 2
                )
                / 0.18
            )
            ch = 1 if name == focus else 0
            np.maximum(frames[:, ch], blob.astype(np.float32), out=frames[:, ch])
        if out is not None:
            out[...] = frames
            return out
        return frames


@dataclass
class ToyTask:
    scene: Scene
    space: ParamSpace
    simulator: ToySimulator
    renderer: ToyRenderer
    observation: Observation


def toy_task(
    params: Sequence[str] = ("mass",), bodies: Sequence[str] | None = None, *, seed: int = 0
) -> ToyTask:
    """The toy problem for ``seed``: truth from :func:`~physbench.loop.draw_problem`, observation
    simulated and rendered, with marked frames for every unknown body."""
    scene = toy_scene()
    space = ParamSpace.from_scene(scene, params, bodies)
    truth, _ = draw_problem(space, seed)
    sim, ren = ToySimulator(), ToyRenderer()
    obs = simulate_observation(scene, truth, sim, ren, marked=space.bodies)
    return ToyTask(scene, space, sim, ren, obs)


def run_toy(
    cls: type,
    options: Mapping[str, Any],
    *,
    seed: int = 0,
    iterations: int = 8,
    params: Sequence[str] = ("mass",),
    bodies: Sequence[str] | None = None,
) -> History:
    """One small :func:`~physbench.loop.refine` of ``cls(**options)`` on :func:`toy_task`."""
    t = toy_task(params, bodies, seed=seed)
    return refine(
        t.observation,
        t.scene,
        t.space,
        t.simulator,
        t.renderer,
        cls(**options),
        iterations=iterations,
        seed=seed,
    )


# --------------------------------------------------------------------------- checks


def _label(cls: type) -> str:
    return f"{cls.__module__}.{cls.__qualname__} (name {getattr(cls, 'name', '?')!r})"


def check_protocol(cls: type, **options: Any) -> None:
    """``name`` is a non-empty string and ``per_object`` a bool on the class; ``cls(**options)``
    builds an object with ``start(task, *, seed)`` and ``propose(step)``."""
    name = getattr(cls, "name", None)
    if not isinstance(name, str) or not name.strip():
        raise ConformanceError(
            f"{_label(cls)}: class attribute 'name' must be a non-empty string, got {name!r}"
        )
    per_object = getattr(cls, "per_object", None)
    if not isinstance(per_object, bool):
        raise ConformanceError(
            f"{_label(cls)}: class attribute 'per_object' must be True or False, got {per_object!r}"
        )
    try:
        est = cls(**options)
    except Exception as exc:
        raise ConformanceError(
            f"{_label(cls)}: {cls.__name__}(**{options!r}) raised {type(exc).__name__}: {exc}"
        ) from exc
    for meth in ("start", "propose"):
        if not callable(getattr(est, meth, None)):
            raise ConformanceError(f"{_label(cls)}: instances need a method {meth}()")
    if not isinstance(est, CorrectionEstimator):
        raise ConformanceError(
            f"{_label(cls)}: instances do not satisfy physbench.CorrectionEstimator"
        )


def check_respects_ranges(cls: type, **options: Any) -> None:
    """Every proposal has exactly the unknowns' keys, finite values inside their ranges, for 1, 2
    and 4 unknowns (the loop itself raises on a bad proposal; this turns that into a finding)."""
    for params, bodies in ((("mass",), ("a",)), (("mass",), None), (("mass", "elasticity"), None)):
        try:
            run_toy(cls, options, seed=1, iterations=8, params=params, bodies=bodies)
        except EstimatorError as exc:
            raise ConformanceError(f"{_label(cls)}: {exc}") from exc


def _trace(h: History) -> dict[str, Any]:
    d: dict[str, Any] = json.loads(json.dumps(h.to_dict(timings=False)))
    d["meta"].pop("observation", None)
    return d


def _first_difference(a: dict[str, Any], b: dict[str, Any]) -> str:
    for ra, rb in zip(a["iterations"], b["iterations"], strict=False):
        if ra != rb:
            return f"iteration {ra['iteration']}: {ra['params']} (loss {ra['loss']}) vs {rb['params']} (loss {rb['loss']})"
    diff = [k for k in a if a[k] != b.get(k)]
    return f"fields {diff}"


def check_deterministic(cls: type, **options: Any) -> None:
    """The same seed twice in this process gives identical histories."""
    a = _trace(run_toy(cls, options, seed=3, params=("mass", "elasticity")))
    b = _trace(run_toy(cls, options, seed=3, params=("mass", "elasticity")))
    if a != b:
        raise ConformanceError(
            f"{_label(cls)}: two runs with seed 3 differ at {_first_difference(a, b)}"
        )


def _import_path(cls: type) -> str:
    if "<locals>" in cls.__qualname__ or cls.__module__ == "__main__":
        raise ConformanceError(
            f"{_label(cls)}: the other-process check re-imports the class as {cls.__module__}:{cls.__qualname__}; "
            "define it at module level in an importable module"
        )
    return f"{cls.__module__}:{cls.__qualname__}"


def check_deterministic_in_subprocess(cls: type, **options: Any) -> None:
    """The same seed in a fresh Python process (another hash seed) gives the identical history.
    Options must be JSON values; the class must be importable at module level."""
    spec = {
        "cls": _import_path(cls),
        "options": options,
        "seed": 5,
        "params": ["mass", "elasticity"],
    }
    try:
        arg = json.dumps(spec)
    except TypeError as exc:
        raise ConformanceError(
            f"{_label(cls)}: options {options!r} must be JSON values for this check ({exc})"
        ) from exc
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(p for p in sys.path if p),
        "PYTHONHASHSEED": "12345",
    }
    proc = subprocess.run(
        [sys.executable, "-c", "from physbench.testing import _child; _child()", arg],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    if proc.returncode != 0:
        raise ConformanceError(
            f"{_label(cls)}: the run in another process failed:\n{proc.stderr.strip()[-2000:]}"
        )
    theirs = json.loads(proc.stdout)
    ours = _trace(run_toy(cls, options, seed=5, params=("mass", "elasticity")))
    if ours != theirs:
        raise ConformanceError(
            f"{_label(cls)}: seed 5 gives a different history in another process, at {_first_difference(ours, theirs)}; "
            "derive all randomness from the seed passed to start()"
        )


def _child() -> None:
    spec = json.loads(sys.argv[1])
    mod, _, qual = spec["cls"].partition(":")
    obj: Any = importlib.import_module(mod)
    for part in qual.split("."):
        obj = getattr(obj, part)
    print(
        json.dumps(
            _trace(run_toy(obj, spec["options"], seed=spec["seed"], params=tuple(spec["params"])))
        )
    )


def _names(exc: BaseException, key: str) -> bool:
    return key in str(exc)


def check_bad_input(
    cls: type, bad_options: Sequence[Mapping[str, Any]] = (), **options: Any
) -> None:
    """Clear errors: an unknown option, ``propose`` before ``start``, and each of ``bad_options``
    raise an exception (not a crash deep inside) whose message names the problem."""
    try:
        cls(**options, no_such_option_xyz=1)
    except Exception as exc:
        if not _names(exc, "no_such_option_xyz"):
            raise ConformanceError(
                f"{_label(cls)}: an unknown option raised {type(exc).__name__}: {exc!s} without naming it"
            ) from exc
    else:
        raise ConformanceError(
            f"{_label(cls)}: an unknown option 'no_such_option_xyz' was accepted silently"
        )

    t = toy_task()
    est = cls(**options)
    step = Step(0, dict(t.observation.truth or {}), t.observation.frames, 0.0)
    try:
        est.propose(step)
    except (PhysbenchError, RuntimeError) as exc:
        if "start" not in str(exc):
            raise ConformanceError(
                f"{_label(cls)}: propose() before start() raised {exc!s}; say that start() must come first"
            ) from exc
    except Exception as exc:
        raise ConformanceError(
            f"{_label(cls)}: propose() before start() raised {type(exc).__name__}: {exc}; raise PhysbenchError "
            "(or RuntimeError) saying start() must come first"
        ) from exc
    else:
        raise ConformanceError(f"{_label(cls)}: propose() before start() did not raise")

    for bad in bad_options:
        try:
            est = cls(**{**options, **bad})
            est.start(
                Task(
                    t.scene,
                    t.space,
                    t.observation.frames,
                    draw_problem(t.space, 0)[1],
                    t.renderer,
                    iterations=8,
                    marked_observation=t.observation.marked,
                ),
                seed=0,
            )
        except (PhysbenchError, ValueError, TypeError) as exc:
            if not any(_names(exc, k) for k in bad):
                raise ConformanceError(
                    f"{_label(cls)}: bad options {dict(bad)} raised {exc!s} without naming the option"
                ) from exc
        else:
            raise ConformanceError(f"{_label(cls)}: bad options {dict(bad)} were accepted")


def check_estimator(
    cls: type,
    /,
    *,
    bad_options: Sequence[Mapping[str, Any]] = (),
    subprocess: bool = True,
    **options: Any,
) -> None:
    """All checks; raises one :class:`ConformanceError` listing every failure."""
    checks: list[tuple[str, Any]] = [
        ("protocol", lambda: check_protocol(cls, **options)),
        ("respects ranges", lambda: check_respects_ranges(cls, **options)),
        ("deterministic", lambda: check_deterministic(cls, **options)),
        ("bad input", lambda: check_bad_input(cls, bad_options, **options)),
    ]
    if subprocess:
        checks.append(
            (
                "deterministic in another process",
                lambda: check_deterministic_in_subprocess(cls, **options),
            )
        )
    failures = []
    for label, fn in checks:
        try:
            fn()
        except ConformanceError as exc:
            failures.append(f"- {label}: {exc}")
            if label == "protocol":
                break  # nothing else can run meaningfully
        except Exception as exc:
            failures.append(f"- {label}: unexpected {type(exc).__name__}: {exc}")
    if failures:
        raise ConformanceError(
            f"{_label(cls)} fails {len(failures)} conformance check(s):\n" + "\n".join(failures)
        )


class EstimatorConformance:
    """pytest base class: subclass it as ``Test...`` and set :attr:`estimator` (and options)."""

    estimator: ClassVar[type | None] = None
    options: ClassVar[Mapping[str, Any]] = {}
    bad_options: ClassVar[Sequence[Mapping[str, Any]]] = ()

    def _cls(self) -> type:
        if self.estimator is None:
            raise ConformanceError(f"{type(self).__name__}: set the class attribute 'estimator'")
        return self.estimator

    def test_protocol(self) -> None:
        check_protocol(self._cls(), **self.options)

    def test_respects_ranges(self) -> None:
        check_respects_ranges(self._cls(), **self.options)

    def test_deterministic(self) -> None:
        check_deterministic(self._cls(), **self.options)

    def test_deterministic_in_subprocess(self) -> None:
        check_deterministic_in_subprocess(self._cls(), **self.options)

    def test_bad_input(self) -> None:
        check_bad_input(self._cls(), self.bad_options, **self.options)
