"""The only hook definitions. A plugin module implements any of them with ``@hookimpl``.

Every hook returns a list of components; the core builds one name-keyed registry per kind. A name
that several plugins claim is a conflict that ``physbench plugins`` reports: physbench's own
component is kept, and between third parties none is used. Components subclass the base class of
their kind (the contract: what the framework calls, and the defaults of every optional member).
Register a plugin through the entry-point group ``physbench``::

    [project.entry-points.physbench]
    myplugin = "my_package.my_module"
"""

from __future__ import annotations

from typing import Any

import pluggy

PROJECT = "physbench"
hookspec = pluggy.HookspecMarker(PROJECT)
hookimpl = pluggy.HookimplMarker(PROJECT)


@hookspec
def register_simulators() -> list[type[Any]]:
    """Return :class:`~physbench.simulators.base.Simulator` subclasses (each with a unique
    ``name``). Called once when the registry is first built."""


@hookspec
def register_renderers() -> list[type[Any]]:
    """Return :class:`~physbench.render.base.Renderer` subclasses. Called once when the registry is
    first built."""


@hookspec
def register_estimators() -> list[type[Any]]:
    """Return :class:`~physbench.estimators.base.CorrectionEstimator` subclasses. Called once when
    the registry is first built."""


@hookspec
def register_scenes() -> list[Any]:
    """Return scene generators: callables ``(seed: int) -> Scene`` with a ``name`` attribute
    (see :func:`physbench.scenes.generator.scene_generator`). Called once when the registry is
    first built."""


@hookspec
def register_effects() -> list[type[Any]]:
    """Return :class:`~physbench.effects.base.Effect` subclasses (model extensions). Called once
    when the registry is first built."""
