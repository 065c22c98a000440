"""The component kinds, declared once: each kind's name, the hook that registers it and the base
class its components subclass. The hook specifications (:mod:`physbench.hookspecs`), the registry
(:mod:`physbench.plugins`), the factory (:mod:`physbench.components`) and the conformance kits
(:mod:`physbench.testing`) all read this table.

Base classes are named as ``"module:Class"`` and imported on first use, so that reading the
table (every ``physbench`` command does) imports no numpy and no engine.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass


@dataclass(frozen=True)
class Kind:
    """One kind of component. ``base`` is ``"module:Class"`` of the contract its components
    subclass, or ``""`` for kinds whose components are plain callables (scene generators)."""

    name: str
    plural: str
    hook: str
    base: str
    #: What the hook returns; the hook specification's docstring.
    returns: str

    def base_class(self) -> type | None:
        """The contract class (imported here, on first use); ``None`` for callables."""
        if not self.base:
            return None
        module, _, qualname = self.base.partition(":")
        return getattr(importlib.import_module(module), qualname)  # type: ignore[no-any-return]


#: Every kind, in the order ``physbench plugins`` lists them.
KINDS: tuple[Kind, ...] = (
    Kind(
        "simulator",
        "simulators",
        "register_simulators",
        "physbench.simulators.base:Simulator",
        "Return :class:`~physbench.simulators.base.Simulator` subclasses (each with a unique "
        "``name``).",
    ),
    Kind(
        "renderer",
        "renderers",
        "register_renderers",
        "physbench.render.base:Renderer",
        "Return :class:`~physbench.render.base.Renderer` subclasses.",
    ),
    Kind(
        "estimator",
        "estimators",
        "register_estimators",
        "physbench.estimators.base:CorrectionEstimator",
        "Return :class:`~physbench.estimators.base.CorrectionEstimator` subclasses.",
    ),
    Kind(
        "scene",
        "scenes",
        "register_scenes",
        "",
        "Return scene generators: callables ``(seed: int) -> Scene`` with a ``name`` attribute "
        "(see :func:`physbench.scenes.generator.scene_generator`).",
    ),
    Kind(
        "effect",
        "effects",
        "register_effects",
        "physbench.effects.base:Effect",
        "Return :class:`~physbench.effects.base.Effect` subclasses (model extensions).",
    ),
)

#: Kind name -> :class:`Kind`.
BY_NAME: dict[str, Kind] = {k.name: k for k in KINDS}


def kind(name: str) -> Kind:
    """The :class:`Kind` called ``name``; an unknown name lists the known ones."""
    try:
        return BY_NAME[name]
    except KeyError:
        from physbench.errors import PhysbenchError

        raise PhysbenchError(
            f"unknown component kind {name!r}; known: {', '.join(BY_NAME)}"
        ) from None


def kind_of_class(cls: object) -> Kind | None:
    """The kind whose base class ``cls`` subclasses (``None``: none does)."""
    for k in KINDS:
        base = k.base_class()
        if base is not None and isinstance(cls, type) and issubclass(cls, base):
            return k
    return None
