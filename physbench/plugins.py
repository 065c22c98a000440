"""The plugin registry: entry points of the group ``physbench`` -> name-keyed registries.

Built-ins are declared in physbench's own ``[project.entry-points.physbench]``, the same path a
third party uses. A plugin that fails to import (or whose hooks fail, or that returns a class that
does not subclass its kind's base class) is recorded in :attr:`Registry.failed` and skipped; two
components of one kind with the same name raise :class:`~physbench.errors.PluginError`.
``PHYSBENCH_PLUGINS="pkg.mod,other.mod"`` registers modules explicitly, without packaging
(Gymnasium's ``module:Name`` idea, as a fallback).
"""

from __future__ import annotations

import importlib
import importlib.metadata as md
import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import pluggy

from physbench import hookspecs
from physbench.errors import PluginError, UnknownNameError

#: Hook name -> component kind.
KINDS: dict[str, str] = {
    "register_simulators": "simulator",
    "register_renderers": "renderer",
    "register_estimators": "estimator",
    "register_scenes": "scene",
    "register_effects": "effect",
}


@dataclass(frozen=True)
class Component:
    kind: str
    name: str
    obj: Any
    plugin: str
    package: str
    version: str


@dataclass(frozen=True)
class FailedPlugin:
    plugin: str
    package: str
    version: str
    error: str


@dataclass
class Registry:
    components: dict[str, dict[str, Component]] = field(
        default_factory=lambda: {k: {} for k in KINDS.values()}
    )
    failed: list[FailedPlugin] = field(default_factory=list)

    def names(self, kind: str) -> list[str]:
        return sorted(self.components[kind])

    def get(self, kind: str, name: str) -> Any:
        """The registered class (or scene generator) ``name`` of ``kind``; unknown names list the
        known."""
        try:
            return self.components[kind][name].obj
        except KeyError:
            raise UnknownNameError(kind, name, self.components[kind]) from None

    def info(self, kind: str, name: str) -> Component:
        self.get(kind, name)
        return self.components[kind][name]

    def all(self) -> list[Component]:
        return [c for kind in KINDS.values() for _, c in sorted(self.components[kind].items())]

    def add(self, comp: Component) -> None:
        known = self.components[comp.kind]
        if comp.name in known:
            old = known[comp.name]
            raise PluginError(
                f"duplicate {comp.kind} name {comp.name!r}: provided by plugin {old.plugin!r} "
                f"({old.package} {old.version}) and by plugin {comp.plugin!r} ({comp.package} "
                f"{comp.version}); "
                "rename one of them or uninstall one package"
            )
        known[comp.name] = comp


def _dist_of(ep: md.EntryPoint) -> tuple[str, str]:
    dist = getattr(ep, "dist", None)
    if dist is None:
        return "?", "?"
    return dist.metadata["Name"] or dist.name, dist.version


def _register(
    pm: pluggy.PluginManager, reg: Registry, plugin: object, name: str, pkg: str, ver: str
) -> bool:
    try:
        pm.register(plugin, name=name)
        pm.check_pending()
    except Exception as exc:  # a plugin may fail in any way; it must never be fatal
        if pm.is_registered(plugin):
            pm.unregister(plugin)
        reg.failed.append(FailedPlugin(name, pkg, ver, f"{type(exc).__name__}: {exc}"))
        return False
    return True


def _bases() -> dict[str, type]:
    """Kind -> the base class its components subclass (scenes are plain callables)."""
    from physbench.effects.base import Effect
    from physbench.estimators.base import CorrectionEstimator
    from physbench.render.base import Renderer
    from physbench.simulators.base import Simulator

    return {
        "simulator": Simulator,
        "renderer": Renderer,
        "estimator": CorrectionEstimator,
        "effect": Effect,
    }


def _contract_breach(kind: str, obj: object, bases: dict[str, type]) -> str | None:
    base = bases.get(kind)
    if base is None:
        return None if callable(obj) else f"returned {obj!r}, which is not callable"
    if not (isinstance(obj, type) and issubclass(obj, base)):
        return (
            f"returned {obj!r}, which does not subclass {base.__module__}.{base.__qualname__} "
            f"(the {kind} contract)"
        )
    return None


def build_registry(
    extra: Iterable[tuple[str, object]] = (), *, entry_points: bool = True, env: bool = True
) -> Registry:
    """Build a registry from the entry points, ``PHYSBENCH_PLUGINS``, and ``extra``
    ``(name, plugin_object)`` pairs (tests register throwaway plugins this way)."""
    pm = pluggy.PluginManager(hookspecs.PROJECT)
    pm.add_hookspecs(hookspecs)
    reg = Registry()
    origin: dict[str, tuple[str, str]] = {}

    if entry_points:
        for ep in sorted(md.entry_points(group=hookspecs.PROJECT), key=lambda e: e.name):
            pkg, ver = _dist_of(ep)
            try:
                plugin = ep.load()
            except Exception as exc:
                reg.failed.append(FailedPlugin(ep.name, pkg, ver, f"{type(exc).__name__}: {exc}"))
                continue
            if _register(pm, reg, plugin, ep.name, pkg, ver):
                origin[ep.name] = (pkg, ver)
    if env:
        for spec in filter(
            None, (s.strip() for s in os.environ.get("PHYSBENCH_PLUGINS", "").split(","))
        ):
            try:
                modname, _, attr = spec.partition(":")
                mod: ModuleType | Any = importlib.import_module(modname)
                plugin = getattr(mod, attr) if attr else mod
            except Exception as exc:
                reg.failed.append(
                    FailedPlugin(spec, "PHYSBENCH_PLUGINS", "-", f"{type(exc).__name__}: {exc}")
                )
                continue
            if _register(pm, reg, plugin, spec, "PHYSBENCH_PLUGINS", "-"):
                origin[spec] = ("PHYSBENCH_PLUGINS", "-")
    for name, plugin in extra:
        if _register(pm, reg, plugin, name, name, "-"):
            origin[name] = (name, "-")

    bases = _bases()
    for hook, kind in KINDS.items():
        for impl in getattr(pm.hook, hook).get_hookimpls():
            pkg, ver = origin.get(impl.plugin_name, ("?", "?"))
            try:
                items = list(impl.function() or [])
            except Exception as exc:
                reg.failed.append(
                    FailedPlugin(
                        impl.plugin_name, pkg, ver, f"{hook} raised {type(exc).__name__}: {exc}"
                    )
                )
                continue
            for obj in items:
                name = getattr(obj, "name", None)  # a plugin's object: checked, not trusted
                breach = _contract_breach(kind, obj, bases)
                if breach is None and (not isinstance(name, str) or not name):
                    breach = f"returned {obj!r} without a string 'name'"
                if breach is not None:
                    reg.failed.append(FailedPlugin(impl.plugin_name, pkg, ver, f"{hook} {breach}"))
                    continue
                reg.add(Component(kind, name, obj, impl.plugin_name, pkg, ver))
    return reg


_REGISTRY: Registry | None = None


def get_registry() -> Registry:
    """The process-wide registry, discovered on first use."""
    global _REGISTRY
    if _REGISTRY is None:
        _REGISTRY = build_registry()
    return _REGISTRY


def reset_registry(registry: Registry | None = None) -> None:
    """Forget (or replace) the cached registry; for tests and long-lived hosts."""
    global _REGISTRY
    _REGISTRY = registry


def create(kind: str, name: str, **options: Any) -> Any:
    """Instantiate the registered component ``name`` of ``kind`` with keyword options; one that
    needs a module not installed here raises
    :class:`~physbench.requirements.MissingDependencyError` naming what to install."""
    from physbench.requirements import require

    cls = get_registry().get(kind, name)
    require(kind, name, cls)
    return cls(**options)
