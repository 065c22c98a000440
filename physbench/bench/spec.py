"""Sweep specs: a TOML file naming the axes of a benchmark, expanded into cells.

A cell is one :class:`~physbench.experiment.RunConfig` (one seed of one configuration). The
product is ``Σ_scenes (scene's unknown sets) × renderer × observer × engine × observe_engine ×
blur × noise × resolution × render_mode × iterations × estimators × seeds``; each scene lists its
own unknown sets because the paper's Table 1 is not a full product. Every axis takes one value or
a list::

    name = "example"
    estimators = ["tpe", "random", {name = "tpe", label = "tpe-20", options = {startup = 20}}]
    seeds = 10                       # 0..9; or a list [3, 7]; or {start = 100, count = 10}
    iterations = 11
    engine = "pymunk"                # the model's simulator
    observe_engine = "box2d"         # the observation's simulator (default: the same as engine)
    blur = [0.0, 1.5]
    noise = 0.0
    resolution = 64
    render_mode = "mark"
    renderer = {name = "mycam", label = "cam-wide", options = {fov = 60}}
                                     # or a name, or a list (default: DEFAULT_RENDERER, no options)
    observer = ["sharp", {name = "camera", label = "phone", options = {bitrate = 2000000}}]
                                     # "sharp": the renderer draws the observation (default); a
                                     # camera renderer: the observation is filmed as an encoded
                                     # video, then tracked and segmented (the visual gap)
    unknowns = ["mass"]              # default for scenes that list none; each item is one set
    effects = []                     # default for scenes that list none: none

    [[scenes]]
    name = "three_circles"           # a registered scene or a scene TOML (relative to this file)
    unknowns = ["mass", "elasticity", "mass+elasticity"]  # a set: also "mass,elasticity",
                                     # "mass elasticity" or ["mass", "elasticity"]
    bodies = ["a"]                   # optional: only these bodies' unknowns

    [[scenes]]
    name = "toss.toml"
    effects = ["linear_drag"]        # simulated with the model and the observation, as
                                     # `physbench run --effect` (NAME[:KEY=NUMBER,...])
    unknowns = ["gravity", "linear_drag.c=0:0.5", "gravity+camera.scale"]
                                     # scene-level keys and KEY=LOW:HIGH ranges, as `run --params`

Unknowns are named as ``physbench run --params`` names them (:mod:`physbench.unknowns`): a body
parameter by its name, a scene-level one (``gravity``, ``camera.scale``, ``camera.clock``, an
effect's ``linear_drag.c``) by its key, either with an optional range ``KEY=LOW:HIGH``.

Seeds: a cell's run seed *is* the seed value, so every configuration sees the same scene
instances, truths and initial guesses (paired comparisons), and ``physbench run ... --seed S``
reproduces a cell exactly.
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import json
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from physbench import numeric
from physbench.errors import PhysbenchError, UnknownNameError
from physbench.experiment import RunConfig
from physbench.limits import MAX_SEED
from physbench.render.base import DEFAULT_RENDERER
from physbench.simulators.base import DEFAULT_SIMULATOR
from physbench.unknowns import split_params

#: The most seeds a spec may list: each is a cell per scene x estimator x axis value, so more is
#: a typo (``seeds = 2**62`` would build the list before anything runs).
MAX_SEEDS = 100_000
AXES = ("engine", "observe_engine", "blur", "noise", "resolution", "render_mode", "iterations")
TOP_KEYS = (
    "name",
    "description",
    "scenes",
    "unknowns",
    "estimators",
    "renderer",
    "observer",
    "seeds",
    "effects",
    *AXES,
)
SCENE_KEYS = ("name", "unknowns", "bodies", "effects")
#: Keys of an estimator or renderer table: ``{name = "...", label = "...", options = {...}}``.
COMPONENT_KEYS = ("name", "label", "options")
DEFAULTS: dict[str, Any] = {
    "engine": DEFAULT_SIMULATOR,
    "observe_engine": None,
    "blur": 0.0,
    "noise": 0.0,
    "resolution": 64,
    "render_mode": "mark",
    "iterations": 11,
    "unknowns": ["mass"],
}


class SpecError(PhysbenchError, ValueError):
    """A sweep spec that cannot be run; the message names the file, key and accepted values."""


@dataclass(frozen=True)
class ComponentSpec:
    """An estimator or a renderer of a spec: its registered name, its label in the tables
    (unique within the axis) and its options."""

    name: str
    label: str
    options: Mapping[str, Any] = field(default_factory=dict)


EstimatorSpec = ComponentSpec
RendererSpec = ComponentSpec
#: The renderer axis of a spec that names none.
DEFAULT_RENDERERS = (RendererSpec(DEFAULT_RENDERER, DEFAULT_RENDERER),)
#: The observer that is no camera: the renderer draws the observation itself.
SHARP = "sharp"
DEFAULT_OBSERVERS = (ComponentSpec(SHARP, SHARP),)


@dataclass(frozen=True)
class SceneSpec:
    name: str  # as written (the table's scene column); ``path`` is what runs
    path: str
    unknowns: tuple[tuple[str, ...], ...]
    bodies: tuple[str, ...] | None = None
    effects: tuple[str, ...] = ()


@dataclass(frozen=True)
class Cell:
    """One run of a sweep. ``index`` is its position in the spec's product (the table's order);
    ``key`` hashes its settings, so it names the cell's result file (the code behind the
    settings is recorded apart, in the cell's stamp: :mod:`physbench.bench.stamp`)."""

    index: int
    config: RunConfig
    scene: str
    label: str  # the estimator's label
    renderer_label: str = DEFAULT_RENDERER
    observer_label: str = SHARP

    @functools.cached_property
    def key(self) -> str:
        return config_key(self.config)


def config_key(config: RunConfig) -> str:
    """The hash of everything in ``config``: the file name of its cell."""
    blob = json.dumps(config.to_dict(), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


@dataclass(frozen=True)
class Spec:
    name: str
    description: str
    scenes: tuple[SceneSpec, ...]
    estimators: tuple[EstimatorSpec, ...]
    seeds: tuple[int, ...]
    axes: Mapping[str, tuple[Any, ...]]
    renderers: tuple[RendererSpec, ...] = DEFAULT_RENDERERS
    source: str = ""  # the TOML text
    path: str = ""
    observers: tuple[ComponentSpec, ...] = DEFAULT_OBSERVERS

    def cells(self) -> list[Cell]:
        """Every cell in product order: scene, unknowns, renderer, observer, axes, estimator,
        seed (seed innermost)."""
        out: list[Cell] = []
        for sc in self.scenes:
            for unknowns in sc.unknowns:
                for ren, obs in itertools.product(self.renderers, self.observers):
                    for values in itertools.product(*(self.axes[a] for a in AXES)):
                        ax = dict(zip(AXES, values, strict=True))
                        for est in self.estimators:
                            for seed in self.seeds:
                                config = RunConfig(
                                    scene=sc.path,
                                    params=unknowns,
                                    estimator=est.name,
                                    options=dict(est.options),
                                    seed=seed,
                                    bodies=sc.bodies,
                                    effects=sc.effects,
                                    renderer=ren.name,
                                    renderer_options=dict(ren.options),
                                    observer=None if obs.name == SHARP else obs.name,
                                    observer_options=dict(obs.options),
                                    **ax,
                                )
                                out.append(
                                    Cell(
                                        len(out),
                                        config,
                                        sc.name,
                                        est.label,
                                        ren.label,
                                        obs.label,
                                    )
                                )
        return out


def _where(path: str, key: str) -> str:
    return f"{path}: {key}" if path else key


def _as_list(value: Any) -> list[Any]:
    return list(value) if isinstance(value, list) else [value]


def _unknown_set(value: Any, where: str) -> tuple[str, ...]:
    try:
        if not isinstance(value, str) and not (
            isinstance(value, list) and all(isinstance(v, str) for v in value)
        ):
            raise PhysbenchError(f"{value!r}")
        return split_params(value)
    except PhysbenchError:
        raise SpecError(
            f'{where} = {value!r}: expected an unknown-parameter set such as "mass", '
            '"mass+elasticity", "mass,elasticity", "mass elasticity" or ["mass", "elasticity"] '
            "(no repeats)"
        ) from None


def _seeds(value: Any, where: str) -> tuple[int, ...]:
    def ok(v: Any) -> bool:
        return isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= MAX_SEED

    def count(v: Any) -> bool:
        return ok(v) and v <= MAX_SEEDS

    if count(value):
        seeds = list(range(value))
    elif isinstance(value, list) and all(ok(v) for v in value):
        seeds = list(value)
    elif (
        isinstance(value, dict)
        and set(value) <= {"start", "count"}
        and ok(value.get("start", 0))
        and count(value.get("count"))
        and value.get("start", 0) + value["count"] - 1 <= MAX_SEED
    ):
        seeds = list(range(value.get("start", 0), value.get("start", 0) + value["count"]))
    else:
        raise SpecError(
            f"{where} = {value!r}: expected a count (50 -> seeds 0..49), a list of whole numbers "
            f"in [0, {MAX_SEED}], or {{start = S, count = N}}, at most {MAX_SEEDS} seeds"
        )
    if len(set(seeds)) != len(seeds):
        raise SpecError(f"{where} = {value!r}: seeds repeat")
    return tuple(seeds)


#: The ranges of the numeric axes (:mod:`physbench.numeric`).
NUMBERS = {
    "blur": numeric.BLUR,
    "noise": numeric.NOISE,
    "resolution": numeric.RESOLUTION,
    "iterations": numeric.COUNT,
}


def _check_axis(name: str, values: list[Any], where: str) -> tuple[Any, ...]:
    def bad(v: Any, expected: str) -> SpecError:
        return SpecError(f"{where} = {v!r}: expected {expected}")

    out = []
    for v in values:
        if name in ("engine", "render_mode") or (name == "observe_engine" and v is not None):
            if not isinstance(v, str) or not v:
                raise bad(v, "a name (string)")
        elif name in NUMBERS:
            if not NUMBERS[name].accepts(v):
                raise bad(v, NUMBERS[name].describe())
            v = float(v) if name in ("blur", "noise") else v
        out.append(v)
    if len(set(out)) != len(out):
        raise SpecError(f"{where} = {values!r}: values repeat")
    return tuple(out)


def _components(value: Any, where: str, kind: str) -> tuple[ComponentSpec, ...]:
    """The estimators or renderers (``kind``) of a spec: names or tables with a name, an optional
    label and options; labels default to ``name(option=value, ...)`` and must be unique."""
    out = []
    for i, item in enumerate(_as_list(value)):
        at = f"{where}[{i}]"
        if isinstance(item, str):
            item = {"name": item}
        if not isinstance(item, dict) or not isinstance(item.get("name"), str):
            raise SpecError(
                f"{at} = {item!r}: expected a registered {kind} name or "
                '{name = "...", label = "...", options = {...}}'
            )
        extra = sorted(set(item) - set(COMPONENT_KEYS))
        if extra:
            raise SpecError(
                f"{at}: unknown key {extra[0]!r}; known keys: {', '.join(COMPONENT_KEYS)}"
            )
        options = item.get("options", {})
        if not isinstance(options, dict):
            raise SpecError(f"{at}.options = {options!r}: expected a table of {kind} options")
        out.append(ComponentSpec(item["name"], str(item.get("label") or ""), options))
    out = [
        ComponentSpec(c.name, c.label or default_label(c.name, c.options), c.options) for c in out
    ]
    labels = [c.label for c in out]
    dup = next((x for x in labels if labels.count(x) > 1), None)
    if dup is not None:
        raise SpecError(f"{where}: two {kind}s are labelled {dup!r}; give each a distinct label")
    same = [(c.name, json.dumps(dict(c.options), sort_keys=True)) for c in out]
    dup2 = next((x for x in same if same.count(x) > 1), None)
    if dup2 is not None:
        raise SpecError(
            f"{where}: {kind} {dup2[0]!r} with options {dup2[1]} appears twice "
            "(it would run the same cells)"
        )
    return tuple(out)


def default_label(name: str, options: Mapping[str, Any]) -> str:
    """``tpe(startup=20)``: a component's label in the tables when the spec gives none."""
    if not options:
        return name
    return name + "(" + ", ".join(f"{k}={v}" for k, v in sorted(options.items())) + ")"


def _effects(value: Any, where: str) -> tuple[str, ...]:
    """A scene's effects: a list of ``--effect`` texts (``NAME[:KEY=NUMBER,...]``)."""
    items = _as_list(value)
    if not all(isinstance(v, str) and v for v in items):
        raise SpecError(
            f"{where} = {value!r}: expected a list of effects such as "
            '["linear_drag", "quadratic_drag:c=0.01"] (NAME[:KEY=NUMBER,...], as run --effect)'
        )
    return tuple(items)


def _scenes(
    value: Any, default_unknowns: Any, default_effects: Any, base: Path, where: str
) -> tuple[SceneSpec, ...]:
    out = []
    for i, item in enumerate(_as_list(value)):
        at = f"{where}[{i}]"
        if isinstance(item, str):
            item = {"name": item}
        if not isinstance(item, dict) or not isinstance(item.get("name"), str):
            raise SpecError(
                f"{at} = {item!r}: expected a scene name or a [[scenes]] table with name and "
                "unknowns"
            )
        extra = sorted(set(item) - set(SCENE_KEYS))
        if extra:
            raise SpecError(f"{at}: unknown key {extra[0]!r}; known keys: {', '.join(SCENE_KEYS)}")
        name = item["name"]
        path = name
        if name.endswith(".toml"):
            p = Path(name) if Path(name).is_absolute() else base / name
            if not p.is_file():
                raise SpecError(f"{at}.name = {name!r}: scene file {str(p)!r} does not exist")
            path = str(p.resolve())
        raw = item.get("unknowns", default_unknowns)
        # Each item is one set: "mass", "mass+elasticity" or ["mass", "elasticity"].
        sets = tuple(_unknown_set(u, f"{at}.unknowns") for u in _as_list(raw))
        if not sets:
            raise SpecError(
                f"{at}.unknowns = []: empty product: the scene lists no unknown-parameter set"
            )
        if len(set(sets)) != len(sets):
            raise SpecError(f"{at}.unknowns = {raw!r}: an unknown set repeats")
        bodies = item.get("bodies")
        if bodies is not None and (
            not isinstance(bodies, list)
            or not all(isinstance(b, str) for b in bodies)
            or not bodies
        ):
            raise SpecError(f"{at}.bodies = {bodies!r}: expected a non-empty list of body names")
        effects = _effects(item.get("effects", default_effects), f"{at}.effects")
        out.append(SceneSpec(name, path, sets, None if bodies is None else tuple(bodies), effects))
    return tuple(out)


def parse_spec(
    data: Mapping[str, Any], *, path: str = "", source: str = "", base: Path | None = None
) -> Spec:
    """A :class:`Spec` from parsed TOML; names are checked against the plugin registry and each
    scene's unknowns, so a bad spec fails before anything runs."""
    base = Path(path).parent if base is None and path else (base or Path.cwd())
    for key in data:
        if key not in TOP_KEYS:
            raise SpecError(
                f"{_where(path, key)}: unknown axis or key {key!r}; known: {', '.join(TOP_KEYS)}"
            )
    for key in ("scenes", "estimators", "seeds"):
        if key not in data:
            raise SpecError(
                f"{_where(path, key)}: missing; a spec needs scenes, estimators and seeds"
            )
    name = data.get("name", Path(path).stem if path else "sweep")
    if not isinstance(name, str) or not name:
        raise SpecError(f"{_where(path, 'name')} = {name!r}: expected a non-empty string")
    description = str(data.get("description", ""))
    scenes = _scenes(
        data["scenes"],
        data.get("unknowns", DEFAULTS["unknowns"]),
        data.get("effects", []),
        base,
        _where(path, "scenes"),
    )
    estimators = _components(data["estimators"], _where(path, "estimators"), "estimator")
    renderers = _components(
        data.get("renderer", DEFAULT_RENDERER), _where(path, "renderer"), "renderer"
    )
    observers = _components(data.get("observer", SHARP), _where(path, "observer"), "observer")
    bad = next((o for o in observers if o.name == SHARP and o.options), None)
    if bad is not None:
        raise SpecError(f"{_where(path, 'observer')}: {SHARP!r} takes no options")
    seeds = _seeds(data["seeds"], _where(path, "seeds"))
    axes = {a: _check_axis(a, _as_list(data.get(a, DEFAULTS[a])), _where(path, a)) for a in AXES}
    empty = [
        k
        for k, v in (
            ("scenes", scenes),
            ("estimators", estimators),
            ("renderer", renderers),
            ("observer", observers),
            ("seeds", seeds),
            *axes.items(),
        )
        if not v
    ]
    if empty:
        raise SpecError(
            f"{_where(path, empty[0])}: empty product: the axis {empty[0]!r} has no values"
        )
    spec = Spec(
        name, description, scenes, estimators, seeds, axes, renderers, source, path, observers
    )
    _check_names(spec)
    # The seeds are distinct (_seeds), so two cells are the same run only when their first seed's
    # cells are: checking those keeps a spec of many seeds quick to load (listing 1e5 seeds'
    # cells takes minutes). Seeds are innermost, so cell i of one seed is cell i * seeds.
    first = replace(spec, seeds=spec.seeds[:1]).cells()
    check_unique([replace(c, index=c.index * len(seeds)) for c in first])
    return spec


def with_renderer(spec: Spec, name: str | None, options: Mapping[str, Any]) -> Spec:
    """``spec`` with its renderer axis replaced (``physbench bench --renderer NAME -R K=V``):
    ``name`` alone, with ``options``; without ``name``, the spec's single renderer with its
    options updated by ``options``. Checked like a spec's own renderer."""
    if name is None:
        if len(spec.renderers) != 1:
            labels = ", ".join(r.label for r in spec.renderers)
            raise SpecError(
                f"--renderer-option without --renderer: the spec has {len(spec.renderers)} "
                f"renderers ({labels}); name the one to run with --renderer NAME"
            )
        name, options = spec.renderers[0].name, {**spec.renderers[0].options, **options}
    ren = RendererSpec(name, default_label(name, options), dict(options))
    out = replace(spec, renderers=(ren,))
    _check_names(out, renderer_where="--renderer")
    return out


def check_unique(cells: list[Cell]) -> None:
    """Refuse a spec that lists the same run twice (e.g. a scene entry repeated)."""
    seen: dict[str, Cell] = {}
    for c in cells:
        if c.key in seen:
            a = seen[c.key]
            raise SpecError(
                f"cells {a.index} and {c.index} are the same run (scene {c.scene!r}, unknowns "
                f"{'+'.join(c.config.params)}, estimator {c.label!r}, seed {c.config.seed}); "
                "remove the repeated entry"
            )
        seen[c.key] = c


def load_spec(path: str | Path) -> Spec:
    """Read and check a spec file."""
    p = Path(path)
    if not p.is_file():
        raise SpecError(f"spec file {str(p)!r} does not exist")
    raw = p.read_bytes()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise SpecError(
            f"{p}: byte {exc.start} ({raw[exc.start : exc.start + 1]!r}) on line {line} is not "
            "UTF-8; spec files are UTF-8 TOML text"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"{p}: not valid TOML: {exc}") from None
    except RecursionError:  # tomllib recurses once per nesting level
        raise SpecError(f"{p}: arrays or tables nested too deeply to parse") from None
    return parse_spec(data, path=str(p), source=text)


def _check_names(spec: Spec, *, renderer_where: str = "") -> None:
    """Build every estimator and renderer once and look up every name, so a bad spec fails
    before anything runs; errors name the spec file and the key."""
    from physbench.components import make_estimator, make_observer, make_renderer
    from physbench.experiment import check_model, config_space
    from physbench.plugins import get_registry
    from physbench.render.sensor import SensorModel
    from physbench.scenes import resolve_scene

    reg = get_registry()
    where = spec.path or spec.name
    try:
        classes = [type(make_estimator(est.name, est.options)) for est in spec.estimators]
        for e in {*spec.axes["engine"], *(v for v in spec.axes["observe_engine"] if v is not None)}:
            reg.get("simulator", e)
        for i, ren in enumerate(spec.renderers):
            at = renderer_where or (f"renderer[{i}]" if len(spec.renderers) > 1 else "renderer")
            try:
                for res, mode in itertools.product(
                    spec.axes["resolution"], spec.axes["render_mode"]
                ):
                    make_renderer(ren.name, ren.options, resolution=res, mode=mode)
            except PhysbenchError as exc:
                raise SpecError(f"{where}: {at} = {ren.name!r}: {exc}") from None
        for i, obs in enumerate(spec.observers):
            if obs.name == SHARP:
                continue
            at = f"observer[{i}]" if len(spec.observers) > 1 else "observer"
            try:
                make_observer(obs.name, obs.options)
            except PhysbenchError as exc:
                raise SpecError(f"{where}: {at} = {obs.name!r}: {exc}") from None
            bad_mode = [
                m for m in spec.axes["render_mode"] if m not in ("mark", "instance", "mask")
            ]
            if bad_mode:
                raise SpecError(
                    f"{where}: {at}: render_mode {bad_mode[0]!r}: a filmed observation is "
                    "segmented into masks (mark, instance or mask)"
                )
        for blur, noise in itertools.product(spec.axes["blur"], spec.axes["noise"]):
            SensorModel(blur=blur, noise=noise)
        for sc in spec.scenes:
            scene = resolve_scene(sc.path, spec.seeds[0])
            for unknowns in sc.unknowns:
                config = RunConfig(
                    scene=sc.path,
                    params=unknowns,
                    bodies=sc.bodies,
                    seed=spec.seeds[0],
                    effects=sc.effects,
                )
                space = config_space(config, scene)
                for cls, obs in itertools.product(classes, spec.observers):
                    check_model(
                        replace(config, observer=None if obs.name == SHARP else obs.name),
                        space,
                        cls,
                    )
    except UnknownNameError as exc:
        raise SpecError(f"{where}: {exc}") from None
    except SpecError:
        raise
    except PhysbenchError as exc:
        raise SpecError(f"{where}: {exc}") from None
