"""The component factory: a registered component built from its kind, its name and options.

Every route that builds a simulator, renderer, estimator or effect by name goes through
:func:`create`: the CLI, the Python API, sweeps, discovery and training-data generation. So a bad
option gets the same sentence everywhere: the option, the options the component takes, and where
the component comes from (:class:`~physbench.errors.OptionError`). Only the refusal of the call
itself becomes that sentence; a ``TypeError`` raised inside a constructor is a fault of the
component (a third party's becomes a :class:`~physbench.plugins.ComponentError`).

:func:`make_renderer` and :func:`make_observer` add the standard keywords of renderers
(``resolution``, ``mode``) and of observer cameras; :func:`make_effect` reads an effect from the
text the command line and sweep specs give it in.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from physbench.errors import OptionError, PhysbenchError
from physbench.kinds import kind as kind_named
from physbench.plugins import OWN, get_registry, guard
from physbench.requirements import require

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.estimators.base import CorrectionEstimator
    from physbench.render.base import Camera, Renderer

#: Image width of an observer camera whose options name no ``resolution``.
OBSERVER_RESOLUTION = 640


def origin(kind: str, name: str) -> str:
    """Where the registered ``kind`` ``name`` comes from, for messages: ``physbench's own`` or
    ``plugin 'x' of package pkg 1.0``."""
    comp = get_registry().info(kind, name)
    if comp.package == OWN:
        return "physbench's own"
    if comp.package == "PHYSBENCH_PLUGINS":
        return f"plugin {comp.plugin!r}, registered by PHYSBENCH_PLUGINS"
    if comp.version == "-":
        return f"plugin {comp.plugin!r}"
    return f"plugin {comp.plugin!r} of package {comp.package} {comp.version}"


def options_of(cls: type, standard: Mapping[str, Any] = {}) -> list[str]:
    """The keyword options ``cls`` takes, less the ``standard`` keywords the framework sets: those
    its ``option_names()`` names (a component whose constructor takes ``**kwargs``, such as an
    effect), else those of its signature."""
    named = getattr(cls, "option_names", None)
    if callable(named):
        return [n for n in named() if n not in standard]
    try:
        params = inspect.signature(cls).parameters.values()
    except (TypeError, ValueError):
        return []
    return [
        p.name
        for p in params
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name not in standard
    ]


def _refusal(cls: type, kwargs: Mapping[str, Any], standard: Mapping[str, Any]) -> str | None:
    """Why the call ``cls(**kwargs)`` itself would be refused (an option it does not take, one it
    needs and lacks), read from its signature; ``None`` when it binds or has no signature."""
    try:
        sig = inspect.signature(cls)
    except (TypeError, ValueError):
        return None
    params = sig.parameters
    if any(p.kind == p.VAR_KEYWORD for p in params.values()):
        if callable(getattr(cls, "option_names", None)):
            known = set(options_of(cls)) | set(standard)
            unknown = [k for k in kwargs if k.rpartition(".")[2] not in known]
            if unknown:
                word = "option" if len(unknown) == 1 else "options"
                return f"does not take {word} {', '.join(repr(k) for k in unknown)}"
    else:
        unknown = [
            k for k in kwargs if k not in params or params[k].kind == params[k].POSITIONAL_ONLY
        ]
        if unknown:
            word = "option" if len(unknown) == 1 else "options"
            return f"does not take {word} {', '.join(repr(k) for k in unknown)}"
    try:
        sig.bind(**kwargs)
    except TypeError as exc:
        missing = [
            p.name
            for p in params.values()
            if p.default is p.empty
            and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
            and p.name not in kwargs
        ]
        if missing:
            return f"needs option {', '.join(repr(k) for k in missing)}"
        return f"refuses these options ({exc})"
    return None


def create(
    kind: str, name: str, options: Mapping[str, Any] | None = None, /, **standard: Any
) -> Any:
    """The registered ``kind`` ``name`` built with the user's ``options`` and the framework's
    ``standard`` keywords (e.g. a renderer's ``resolution``). Raises
    :class:`~physbench.errors.UnknownNameError` for an unknown name,
    :class:`~physbench.requirements.MissingDependencyError` when a module it needs is missing,
    and :class:`~physbench.errors.OptionError` when it does not take the options or refuses
    their values (a ``ValueError`` of its own checks)."""
    kind_named(kind)
    cls = get_registry().get(kind, name)
    require(kind, name, cls)
    opts = dict(options or {})
    kwargs = {**opts, **standard}

    def refused(why: str) -> OptionError:
        takes = ", ".join(options_of(cls, standard)) or "none"
        if standard:
            takes += f" (besides {', '.join(standard)}, which physbench sets)"
        return OptionError(f"{kind} {name!r} ({origin(kind, name)}) {why}; its options: {takes}")

    why = _refusal(cls, kwargs, standard)
    if why is not None:
        raise refused(why)
    with guard(kind, cls, "__init__()"):
        try:
            return cls(**kwargs)
        except PhysbenchError:
            raise
        except TypeError as exc:
            if exc.__traceback__ is not None and exc.__traceback__.tb_next is None:
                raise refused(f"refuses these options ({exc})") from None  # the call itself
            raise
        except ValueError as exc:  # a component's own check of a value
            raise OptionError(
                f"{kind} {name!r} ({origin(kind, name)}) refused options {opts}: {exc}"
            ) from None


def make_estimator(name: str, options: Mapping[str, Any] | None = None) -> CorrectionEstimator:
    """The registered estimator ``name`` with ``options``."""
    return create("estimator", name, options)  # type: ignore[no-any-return]


def default_render_mode(name: str) -> str:
    """The channel layout of the registered renderer ``name`` when none is asked for: the first
    it declares (``mark`` for raster, ``rgb`` for camera)."""
    return str(get_registry().get("renderer", name).modes[0])


def make_renderer(
    name: str,
    options: Mapping[str, Any] | None = None,
    *,
    resolution: int | tuple[int, int],
    mode: str | None,
) -> Renderer:
    """The registered renderer ``name`` with its ``options`` and the standard ``resolution`` and
    ``mode`` (``None``: :func:`default_render_mode`)."""
    clash = sorted({"resolution", "mode"} & set(options or {}))
    if clash:
        raise OptionError(
            f"renderer option {clash[0]!r}: set it with --resolution / --render-mode (in a sweep "
            "spec: the resolution and render_mode axes), not as a renderer option"
        )
    if mode is None:
        mode = default_render_mode(name)
    return create("renderer", name, options, resolution=resolution, mode=mode)  # type: ignore[no-any-return]


def make_observer(name: str, options: Mapping[str, Any] | None = None) -> Camera:
    """The camera that films a simulated observation: the registered renderer ``name``, which
    must be a :class:`~physbench.render.base.Camera` (the video path needs its plate and true
    calibration); its ``options`` may hold ``resolution`` (default
    :data:`OBSERVER_RESOLUTION`). It draws ``rgb`` frames."""
    from physbench.render.base import Camera

    cls = get_registry().get("renderer", name)
    if not (isinstance(cls, type) and issubclass(cls, Camera)):
        raise PhysbenchError(
            f"observer {name!r} is a {cls.__name__}; an observer films the observation as a "
            "video, so it must be a camera (a physbench.render.base.Camera, e.g. 'camera')"
        )
    opts = dict(options or {})
    resolution = opts.pop("resolution", OBSERVER_RESOLUTION)
    return create("renderer", name, opts, resolution=resolution, mode="rgb")  # type: ignore[no-any-return]


def make_effect(text: str, *, where: str = "--effect") -> Effect:
    """The registered effect of ``text``, ``NAME[:KEY=NUMBER,...]`` (``linear_drag:c=0.3``: its
    parameters' values when not unknown), as ``physbench simulate --effect`` and ``physbench run
    --effect`` take it; ``where`` names the setting in the error."""
    from physbench.numeric import ANY

    name, _, rest = text.partition(":")
    values: dict[str, float] = {}
    for pair in filter(None, (p.strip() for p in rest.split(","))):
        key, sep, value = pair.partition("=")
        try:
            if not sep or not key.strip():
                raise ValueError
            values[key.strip()] = float(ANY.parse(value))
        except ValueError:
            raise PhysbenchError(
                f"{where} {text!r}: expected NAME[:KEY=NUMBER,...] with finite numbers, e.g. "
                "linear_drag:c=0.3"
            ) from None
    return create("effect", name.strip(), values)  # type: ignore[no-any-return]
