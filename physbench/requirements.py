"""Optional dependencies of a plugin component: what it imports when it runs, checked before the
framework builds it, so a missing extra is one sentence naming what to install, not a traceback
from deep inside a run."""

from __future__ import annotations

import importlib.util
from collections.abc import Mapping
from types import MappingProxyType
from typing import ClassVar

from physbench.errors import PhysbenchError


class MissingDependencyError(PhysbenchError, ImportError):
    """A component needs a module that is not installed."""


class Requirements:
    """Mixin of every component base class (simulator, renderer, estimator, effect)."""

    #: Modules the component imports when it runs -> the pip requirement that installs them
    #: (e.g. ``{"torch": "physbench[learn]"}``); default none.
    requires: ClassVar[Mapping[str, str]] = MappingProxyType({})

    @classmethod
    def missing(cls) -> dict[str, str]:
        """Called by the registry before it builds the component, and by ``physbench plugins``:
        the entries of :attr:`requires` whose module cannot be imported here (default: those
        :func:`importlib.util.find_spec` does not find)."""
        return {mod: req for mod, req in cls.requires.items() if not _importable(mod)}


def _importable(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a parent that is missing, or a module set to None
        return False


def missing_of(obj: object) -> dict[str, str]:
    """The missing modules of a registered class (``{}`` for scene generators and plain callables
    that declare nothing)."""
    missing = getattr(obj, "missing", None)
    if isinstance(obj, type) and issubclass(obj, Requirements) and callable(missing):
        return dict(missing())
    return {}


def unavailable(kind: str, name: str, missing: Mapping[str, str]) -> MissingDependencyError:
    """The error for a ``kind`` ``name`` whose ``missing`` modules are absent."""
    modules = ", ".join(sorted(missing))
    install = " ".join(f"'{r}'" for r in dict.fromkeys(sorted(missing.values())))
    verb = "is" if len(missing) == 1 else "are"
    return MissingDependencyError(
        f"{kind} {name!r} needs {modules}, which {verb} not installed: pip install {install}"
    )


def require(kind: str, name: str, obj: object) -> None:
    """Raise :class:`MissingDependencyError` when the registered ``obj`` cannot run here."""
    missing = missing_of(obj)
    if missing:
        raise unavailable(kind, name, missing)
