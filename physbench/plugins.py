"""The plugin registry: entry points of the group ``physbench`` -> name-keyed registries.

Built-ins are declared in physbench's own ``[project.entry-points.physbench]``, the same path a
third party uses. A plugin that fails to import (or whose hooks fail, or that returns a class that
does not subclass its kind's base class) is recorded in :attr:`Registry.failed` and skipped. Two
components of one kind with the same name are a :class:`Conflict`: physbench's own wins over a third
party's, and between third parties neither is used, so one bad package never stops the command.
What a third party's component raises when the framework calls it becomes a
:class:`ComponentError` naming the component, its plugin and its package (:func:`guard`).
``PHYSBENCH_PLUGINS="pkg.mod,other.mod"`` registers modules explicitly, without packaging
(Gymnasium's ``module:Name`` idea, as a fallback).
"""

from __future__ import annotations

import importlib
import importlib.metadata as md
import os
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import pluggy

from physbench import hookspecs
from physbench.errors import (
    PhysbenchError,
    PhysbenchWarning,
    PluginError,
    UnknownNameError,
    counted,
)
from physbench.kinds import KINDS

#: The package name of physbench's own components: a conflict keeps them, and what they raise is
#: physbench's bug, not a plugin's.
OWN = "physbench"


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


def _who(c: Component) -> str:
    return f"plugin {c.plugin!r} ({c.package} {c.version})"


def _source(f: FailedPlugin) -> str:
    """Where a failed plugin came from, for messages."""
    if f.package == "PHYSBENCH_PLUGINS":
        return "named in PHYSBENCH_PLUGINS"
    return f"package {f.package} {f.version}"


@dataclass(frozen=True)
class Conflict:
    """Components of one kind that share a name. ``kept`` is physbench's own, or ``None`` when
    every side is a third party's (then none of them is used)."""

    kind: str
    name: str
    kept: Component | None
    ignored: tuple[Component, ...]

    def describe(self) -> str:
        if self.kept is not None:
            return (
                f"{self.kind} {self.name!r} is physbench's own; the one of "
                f"{', '.join(_who(c) for c in self.ignored)} is ignored: rename it in that package "
                "or uninstall it"
            )
        return (
            f"{self.kind} {self.name!r} is provided by "
            f"{' and by '.join(_who(c) for c in self.ignored)}; none of them is used: rename it "
            "in all but one package or uninstall all but one"
        )


class PluginWarning(PhysbenchWarning):
    """A plugin's component that is not used: another one of the same kind and name (physbench's
    own) is used in its place."""


class ComponentError(PluginError):
    """A third party's component raised (or called ``sys.exit``) where the framework called
    it; the message names the component, its plugin and its package."""

    def __init__(self, component: Component, call: str, exc: BaseException) -> None:
        self.component, self.call = component, call
        what = type(exc).__name__ + (f": {exc}" if str(exc) else "")
        super().__init__(
            f"{component.kind} {component.name!r} of {_who(component)} failed in {call}: {what}; "
            "this is a fault of that plugin: report it to its authors (rerun with --debug for the "
            "traceback)"
        )


@dataclass
class Registry:
    components: dict[str, dict[str, Component]] = field(
        default_factory=lambda: {k.name: {} for k in KINDS}
    )
    failed: list[FailedPlugin] = field(default_factory=list)
    conflicts: list[Conflict] = field(default_factory=list)
    #: (kind, name) of the shadowed components already warned about (once each)
    _warned: set[tuple[str, str]] = field(default_factory=set, repr=False)

    def names(self, kind: str) -> list[str]:
        return sorted(self.components[kind])

    def get(self, kind: str, name: str) -> Any:
        """The registered class (or scene generator) ``name`` of ``kind``. An unknown name lists
        the known ones and the plugins that failed to load (one of them may have provided it);
        a name that a plugin also claims is physbench's own, and the first use of it warns
        (:class:`PluginWarning`) that the plugin's is not used."""
        try:
            found = self.components[kind][name].obj
        except KeyError:
            for c in self.conflicts:
                if (c.kind, c.name) == (kind, name):
                    raise PluginError(c.describe()) from None
            raise UnknownNameError(
                kind, name, self.components[kind], hint=self.failures_hint(name)
            ) from None
        self._warn_shadowed(kind, name)
        return found

    def failures_hint(self, name: str = "") -> str:
        """A sentence on the plugins that failed to load, those whose name contains ``name``
        first ("" when none failed): an unknown name may be one of theirs."""
        if not self.failed:
            return ""
        ranked = sorted(self.failed, key=lambda f: name.lower() not in f.plugin.lower())
        shown = "; ".join(f"{f.plugin} ({_source(f)}): {f.error}" for f in ranked[:3])
        more = f"; {len(ranked) - 3} more" if len(ranked) > 3 else ""
        return (
            f"{counted(len(ranked), 'plugin')} failed to load and may have provided it: "
            f"{shown}{more} (see `physbench plugins`)"
        )

    def _warn_shadowed(self, kind: str, name: str) -> None:
        """Warn once that a plugin's ``kind`` ``name`` is ignored in favour of physbench's own."""
        if (kind, name) in self._warned:
            return
        for c in self.conflicts:
            if (c.kind, c.name) == (kind, name) and c.kept is not None:
                import warnings

                self._warned.add((kind, name))
                warnings.warn(c.describe(), PluginWarning, stacklevel=3)

    def info(self, kind: str, name: str) -> Component:
        self.get(kind, name)
        return self.components[kind][name]

    def all(self) -> list[Component]:
        return [c for kind in KINDS for _, c in sorted(self.components[kind.name].items())]

    def add(self, comp: Component) -> None:
        """Add one component; a name already taken raises :class:`PluginError`
        (:func:`build_registry` turns those into conflicts before adding)."""
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

    def owner(self, kind: str, obj: object) -> Component | None:
        """The registered component ``obj`` is (a scene generator) or is an instance of."""
        for comp in self.components[kind].values():
            if comp.obj is obj or comp.obj is type(obj):
                return comp
        return None

    def _resolve(self, candidates: list[Component]) -> None:
        """Add every candidate; a name that several share becomes a :class:`Conflict`."""
        by_name: dict[tuple[str, str], list[Component]] = {}
        for comp in candidates:
            by_name.setdefault((comp.kind, comp.name), []).append(comp)
        for (kind, name), comps in by_name.items():
            own = [c for c in comps if c.package == OWN]
            if len(comps) == 1:
                self.add(comps[0])
                continue
            kept = own[0] if len(own) == 1 else None
            if kept is not None:
                self.add(kept)
            ignored = tuple(c for c in comps if c is not kept)
            self.conflicts.append(Conflict(kind, name, kept, ignored))


@contextmanager
def guard(kind: str, obj: object, call: str) -> Iterator[None]:
    """Around each call the framework makes into a component: what a third party's component
    raises, ``SystemExit`` included, becomes a :class:`ComponentError`. Physbench's own errors and
    those of physbench's own components (its bugs) pass unchanged."""
    try:
        yield
    except PhysbenchError:
        raise
    except (Exception, SystemExit) as exc:
        comp = get_registry().owner(kind, obj)  # looked up only on failure: the call stays cheap
        if comp is None or comp.package == OWN:
            raise
        raise ComponentError(comp, call, exc) from exc


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
    except (Exception, SystemExit) as exc:  # a plugin may fail in any way; never fatal
        if pm.is_registered(plugin):
            pm.unregister(plugin)
        reg.failed.append(FailedPlugin(name, pkg, ver, f"{type(exc).__name__}: {exc}"))
        return False
    return True


def _contract_breach(kind: str, obj: object, bases: dict[str, type | None]) -> str | None:
    base = bases[kind]
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
            except (Exception, SystemExit) as exc:  # sys.exit() at import included
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
            except (Exception, SystemExit) as exc:
                reg.failed.append(
                    FailedPlugin(spec, "PHYSBENCH_PLUGINS", "-", f"{type(exc).__name__}: {exc}")
                )
                continue
            if _register(pm, reg, plugin, spec, "PHYSBENCH_PLUGINS", "-"):
                origin[spec] = ("PHYSBENCH_PLUGINS", "-")
    for name, plugin in extra:
        if _register(pm, reg, plugin, name, name, "-"):
            origin[name] = (name, "-")

    bases = {k.name: k.base_class() for k in KINDS}
    candidates: list[Component] = []
    for k in KINDS:
        hook, kind = k.hook, k.name
        for impl in getattr(pm.hook, hook).get_hookimpls():
            pkg, ver = origin.get(impl.plugin_name, ("?", "?"))
            try:
                items = list(impl.function() or [])
            except (Exception, SystemExit) as exc:
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
                candidates.append(Component(kind, name, obj, impl.plugin_name, pkg, ver))
    reg._resolve(candidates)
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


def blame(exc: BaseException) -> tuple[Component, str] | None:
    """The third party's component whose package raised ``exc`` and the function that raised it
    (the innermost frame in such a package's modules); ``None`` when none did or no registry
    was built. For the CLI's last guard, behind the explicit :func:`guard` calls."""
    if _REGISTRY is None:
        return None
    tops = {
        str(getattr(c.obj, "__module__", "")).partition(".")[0]: c
        for c in _REGISTRY.all()
        if c.package != OWN
    }
    tops.pop("", None)
    found = None
    tb = exc.__traceback__
    while tb is not None:  # outermost to innermost: the last match is where it was raised
        top = str(tb.tb_frame.f_globals.get("__name__", "")).partition(".")[0]
        if top in tops:
            found = tops[top], f"{tb.tb_frame.f_code.co_name}()"
        tb = tb.tb_next
    return found
