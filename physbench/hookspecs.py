"""The only hook definitions, one per component kind of :data:`physbench.kinds.KINDS` (so a new
kind is one row there). A plugin module implements any of them with ``@hookimpl``:

``register_simulators``, ``register_renderers``, ``register_estimators``, ``register_scenes``,
``register_effects``: each returns a list of components and is called once, when the registry is
first built. The core builds one name-keyed registry per kind. A name that several plugins claim
is a conflict that ``physbench plugins`` reports: physbench's own component is kept, and between
third parties none is used. Components subclass the base class of their kind (the contract: what
the framework calls, and the defaults of every optional member). Register a plugin through the
entry-point group ``physbench``::

    [project.entry-points.physbench]
    myplugin = "my_package.my_module"
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pluggy

from physbench.kinds import KINDS, Kind

PROJECT = "physbench"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


def _spec(kind: Kind) -> Callable[[], list[Any]]:
    def hook() -> list[Any]: ...

    hook.__name__ = hook.__qualname__ = kind.hook
    hook.__module__ = __name__
    hook.__doc__ = f"{kind.returns} Called once when the registry is first built."
    return hookspec(hook)  # type: ignore[no-any-return]


for _kind in KINDS:
    globals()[_kind.hook] = _spec(_kind)
del _kind
