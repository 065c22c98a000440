"""The public Python entry points: what ``import physbench`` offers a script or a notebook.

Each function is a thin front over the machinery the commands use, so Python and the command
line give the same results for the same settings::

    import physbench

    if __name__ == "__main__":  # needed by sweep(): its worker processes re-run this script
        scene = physbench.make_scene("three_circles", seed=0)        # physbench scenes
        traj = physbench.simulate(scene, engine="pymunk")             # physbench simulate
        frames = physbench.render_frames(scene, traj, resolution=64)
        history = physbench.run(scene="three_circles", iterations=5)  # physbench run
        result = physbench.sweep(physbench.example("smoke"), "out/")  # physbench bench
        table = physbench.load_table("out/")                          # results.parquet, flat
        found = physbench.discover_effects("rec.csv", "scene.toml")   # physbench discover

A script that calls :func:`sweep` with worker processes (the default) must do so under
``if __name__ == "__main__":``: each worker starts by running the script again (Python's
``spawn``), and would start the sweep again; a sweep started outside the guard is refused before
any cell runs, naming the line.

:func:`refine` is :func:`physbench.loop.refine` (the loop with every part given as an object).
The names differ from the commands where a command's name is already a module of the package
(``physbench.scene``, ``physbench.render``, ``physbench.bench``, ``physbench.discover``): Python
rebinds a package attribute to its submodule whenever that submodule is imported, so a function
of the same name would be replaced by the module behind the user's back.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from physbench.errors import PhysbenchError
from physbench.loop import refine
from physbench.recording import read_recording
from physbench.render.base import DEFAULT_RENDERER
from physbench.simulators.base import DEFAULT_SIMULATOR

if TYPE_CHECKING:
    import numpy as np
    import pandas as pd

    from physbench.bench.runner import SweepResult
    from physbench.bench.spec import Spec
    from physbench.discover.results import Discovery
    from physbench.effects.base import Effect
    from physbench.loop import History
    from physbench.recording import Recording
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

__all__ = [
    "discover_effects",
    "example",
    "load_table",
    "make_scene",
    "read_recording",
    "refine",
    "render_frames",
    "run",
    "simulate",
    "sweep",
]

#: Image width of :func:`render_frames` when none is asked for (``physbench simulate``'s).
RESOLUTION = 64
#: Column prefixes of :func:`load_table`'s flat table (Optuna's ``params_x`` habit).
FLAT_COLUMNS = ("params", "truth")

#: Effects as :func:`simulate` takes them: instances, registered names, or name -> options.
Effects = Iterable["Effect | str"] | Mapping[str, Mapping[str, float]]


def make_scene(name_or_path: str | Path, seed: int = 0) -> Scene:
    """The scene a registered generator makes for ``seed``, or the scene of a TOML file (whose
    instance does not depend on ``seed``); unknown names list the registered ones.

    Example::

        scene = physbench.make_scene("three_circles", seed=3)
        scene.body_names  # ('test', 'a', 'b')
    """
    from physbench import numeric
    from physbench.scenes import resolve_scene

    return resolve_scene(str(name_or_path), int(numeric.SEED.check(seed, "seed")))


def _scene(scene: Scene | str | Path) -> Scene:
    return make_scene(scene) if isinstance(scene, str | Path) else scene


def _effects(effects: Effects) -> list[Effect]:
    from physbench.components import create

    if isinstance(effects, Mapping):
        return [create("effect", name, opts) for name, opts in effects.items()]
    if isinstance(effects, str):  # one name, not its letters
        effects = [effects]
    return [create("effect", e) if isinstance(e, str) else e for e in effects]


def simulate(
    scene: Scene | str | Path,
    engine: str = DEFAULT_SIMULATOR,
    params: Mapping[str, float] | None = None,
    effects: Effects = (),
) -> Trajectory:
    """Simulate ``scene`` (a :class:`~physbench.scene.Scene`, or a name or TOML path for
    :func:`make_scene` at seed 0) with the registered ``engine``. ``params`` overrides body
    parameters (``{"a.mass": 3.0}``); ``effects`` adds physics the scene lacks: effect objects,
    registered names, or ``{"linear_drag": {"c": 0.3}}``. Measurement effects (sensor offsets,
    clock errors) are applied to the returned trajectory, as ``physbench simulate`` does.

    Example::

        traj = physbench.simulate("ball_drop", effects={"linear_drag": {"c": 0.3}})
        traj.states.shape  # (frames, bodies, x y angle vx vy omega)
    """
    from physbench.components import create
    from physbench.effects import apply_measurements

    sc = _scene(scene)
    overrides = dict(params or {})
    if overrides:  # refused by name (NaN, out of range, unknown key), before an engine sees them
        sc.with_params(overrides).validate()
    made = _effects(effects)
    traj = create("simulator", engine).simulate(sc, overrides, effects=made)
    return apply_measurements(traj, made) if made else traj


def render_frames(
    scene: Scene | str | Path,
    trajectory: Trajectory,
    renderer: str = DEFAULT_RENDERER,
    *,
    resolution: int = RESOLUTION,
    mode: str | None = None,
    **options: Any,
) -> np.ndarray:
    """Frames ``(T, C, H, W)`` in [0, 1] of ``trajectory`` drawn by the registered ``renderer``
    ``resolution`` pixels wide in channel layout ``mode`` (default: the renderer's first, e.g.
    ``mark`` for raster, ``rgb`` for camera); ``options`` are the renderer's own (its
    ``-R KEY=VALUE`` on the command line).

    Example::

        frames = physbench.render_frames(scene, traj, "camera", resolution=160, tilt=10)
    """
    from physbench.components import make_renderer

    r = make_renderer(renderer, options, resolution=resolution, mode=mode)
    return r.render(_scene(scene), trajectory)


def _config_settings(settings: Mapping[str, Any]) -> dict[str, Any]:
    """``run``'s keywords as :class:`~physbench.experiment.RunConfig` fields: a single parameter,
    body or effect may be given as a string, lists as tuples, the scene file as a path."""
    from physbench.experiment import RunConfig

    known = [f.name for f in fields(RunConfig)]
    extra = sorted(set(settings) - set(known))
    if extra:
        raise PhysbenchError(f"run(): unknown settings {extra}; known: {', '.join(known)}")
    kw = dict(settings)
    scene = kw.get("scene")
    if isinstance(scene, Path):
        kw["scene"] = str(scene)
    elif scene is not None and not isinstance(scene, str):
        # a run is data (sweeps hash it), so it names its scene rather than holding one
        raise PhysbenchError(
            f"run(scene={type(scene).__name__}): expected a registered scene name or a scene "
            "TOML path; write a Scene object with physbench.scene_toml.save_scene first"
        )
    if kw.get("params") is not None:
        from physbench.unknowns import split_params

        kw["params"] = split_params(kw["params"])  # "mass+elasticity" as on the command line
    for key in ("bodies", "effects"):
        value = kw.get(key)
        if isinstance(value, str):
            kw[key] = (value,)
        elif value is not None and key in kw:
            kw[key] = tuple(value)
    return kw


def run(**settings: Any) -> History:
    """One run of the correction loop, as ``physbench run`` does it: the settings are the fields
    of :class:`~physbench.experiment.RunConfig` (``scene``, ``params``, ``estimator``,
    ``options``, ``seed``, ``iterations``, ``engine``, ``renderer``, ``resolution``, ...), with
    the same defaults. An unknown that moves no pixel is named in a :class:`UserWarning` and kept
    in ``History.unseen``. ``params`` may name scene-level unknowns by key and give any unknown a
    range, as ``--params`` does (``"gravity=-11:-9"``); ``effects`` are ``--effect`` texts.

    Example::

        h = physbench.run(scene="three_circles", params="mass", estimator="cmaes", iterations=5)
        h.truth, h.best.params, h.best_nmse
        g = physbench.run(scene="toss.toml", video="toss.mp4", params="gravity", iterations=40)
        d = physbench.run(scene="toss.toml", effects="linear_drag", params="linear_drag.c=0:0.5")
    """
    import warnings

    from physbench.experiment import RunConfig, run_config

    config = RunConfig(**_config_settings(settings))
    return run_config(config, notice=lambda text: warnings.warn(text, UserWarning, stacklevel=3))


def example(name: str) -> Path:
    """The spec file of a sweep that ships with physbench (``physbench bench --example NAME``):
    ``"smoke"``, the quick start's sweep. Unknown names list the shipped ones.

    Example::

        physbench.sweep(physbench.example("smoke"), "smoke")  # under if __name__ == "__main__"
    """
    from physbench.examples import example_path

    return example_path(name)


def sweep(
    spec: str | Path | Mapping[str, Any] | Spec,
    out: str | Path,
    *,
    executor: str = "processes",
    workers: int | None = None,
    fresh: bool = False,
    retry_failed: bool = False,
    allow_stale: bool = False,
    progress: bool = False,
) -> SweepResult:
    """Run a sweep spec into the folder ``out`` as ``physbench bench SPEC --out DIR`` does
    (resuming the cells already there). ``spec``: a TOML file, the same content as a dict, or a
    parsed :class:`~physbench.bench.spec.Spec`; ``executor``: ``serial`` (this process),
    ``processes`` or ``dask``. Read the table back with :func:`load_table`. Raises
    :class:`~physbench.bench.runner.SweepFailedError` when every cell failed (the tables, with
    each cell's error, are written first).

    With worker processes (``processes``, a local ``dask`` cluster) a script must call it under
    ``if __name__ == "__main__":``, since each worker starts by running the script again (Python's
    ``spawn``); a call outside the guard is refused before any cell runs.

    Example::

        import physbench

        if __name__ == "__main__":
            res = physbench.sweep({"scenes": [{"name": "three_circles", "unknowns": ["mass"]}],
                                   "estimators": ["random"], "seeds": 2, "iterations": 3}, "out")
            print(res.stats[["scene", "estimator", "mean"]])
    """
    from physbench.bench.runner import run_sweep
    from physbench.bench.spec import Spec, load_spec, parse_spec

    if isinstance(spec, Mapping):
        spec = parse_spec(spec)
    elif not isinstance(spec, Spec):
        spec = load_spec(spec)
    return run_sweep(
        spec,
        out,
        executor=executor,
        workers=workers,
        fresh=fresh,
        retry_failed=retry_failed,
        allow_stale=allow_stale,
        progress=progress,
    )


def load_table(out: str | Path, *, flat: bool = True) -> pd.DataFrame:
    """A sweep's long table (one row per cell x iteration) from its folder or its
    ``results.parquet``. ``flat``: the JSON ``params`` and ``truth`` columns spread into one
    float column per parameter, ``params_a.mass``, ``truth_a.mass`` (missing where a cell has no
    such unknown), like Optuna's ``trials_dataframe()``; ``flat=False``: the table as stored.

    Example::

        df = physbench.load_table("out")
        df.groupby("estimator")["best_nmse"].mean()
    """
    import pandas as pd

    from physbench.bench.runner import read_table
    from physbench.bench.tables import param_frame

    df = read_table(out)
    if not flat:
        return df
    parts = [
        param_frame(df, c).add_prefix(f"{c}_") if c in FLAT_COLUMNS else df[[c]] for c in df.columns
    ]
    return pd.concat(parts, axis=1)


def discover_effects(
    recording: str | Path | Recording | Sequence[Recording],
    scene: Scene | str | Path,
    *,
    engine: str = DEFAULT_SIMULATOR,
    run: str | None = None,
    **settings: Any,
) -> Discovery:
    """Fit ``scene`` (a :class:`~physbench.scene.Scene`, TOML file or registered name, with the
    unknowns to fit) to ``recording`` and name the missing effect(s), as ``physbench discover``
    does. ``recording``: a file (recording ``.csv``, frames ``.npz`` or a video, see
    :func:`~physbench.discover.data.load_runs`) or :class:`~physbench.recording.Recording`
    objects; ``run`` keeps one run of a multi-run CSV. ``settings`` are the fields of
    :class:`~physbench.discover.Settings` (``effects``, ``holdout``, ``min_gain``, ...).

    Example::

        found = physbench.discover_effects("rec.csv", "slide.toml", effects=["linear_drag"])
        found.causes, found.gain
    """
    from physbench.discover import Run, Settings, discover, load_runs

    known = [f.name for f in fields(Settings)]
    extra = sorted(set(settings) - set(known))
    if extra:
        raise PhysbenchError(
            f"discover_effects(): unknown settings {extra}; known: {', '.join(known)}"
        )
    checked = Settings(**settings)  # a bad setting is refused before the data are read
    sc = _scene(scene).validate()
    if isinstance(recording, str | Path):
        runs = load_runs(recording, sc, run=run)
    else:
        recs = [recording] if not isinstance(recording, Sequence) else list(recording)
        if run is not None:
            recs = [r for r in recs if r.run == run]
        if not recs:
            raise PhysbenchError(f"discover_effects(): no recording (run={run!r})")
        runs = [
            Run(r.run or f"run{i}", sc, recording=r, source=r.source) for i, r in enumerate(recs)
        ]
    return discover(runs, engine, settings=checked)
