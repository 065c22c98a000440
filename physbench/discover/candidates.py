"""The candidate model extensions for a scene: which registered effects apply and to which bodies,
and where their parameters start (where the effect changes nothing, so that a candidate fit starts
from the current model).

Rules for the built-ins: translational losses (``linear_drag``, ``quadratic_drag``,
``rolling_resistance``) act on free bodies only: on a body hanging from a pivot they are the joint
losses again (for one arm, drag on the centre of mass *is* viscous or quadratic joint damping and
rolling resistance *is* Coulomb friction), which the joint effects describe. Contact laws need
static geometry or a second body. ``rolling_resistance`` needs a surface to roll on: a top-down
scene (gravity 0) or static geometry; a ball falling through air has none. On bodies that all
have one mass, ``constant_force`` and ``table_tilt`` are the same uniform acceleration: only one
is offered (``table_tilt`` seen from above, ``constant_force`` in a side view, where it is a
change of gravity). ``clock_scale`` needs a force of known size (a scheduled kick) in the scene:
without one, a clock error is a change of gravity (or of a pendulum's inertia) and of the initial
speeds, which the base model or other candidates already describe. Any other effect
(third-party ones included) is a candidate when its ``setup`` accepts the scene.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from physbench.errors import PhysbenchError, UnknownNameError

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.scene import Scene

#: Effects that act on a body's translation like a loss; offered for free bodies only.
TRANSLATIONAL_LOSSES = ("linear_drag", "quadratic_drag", "rolling_resistance")
CONTACT_LAWS = ("velocity_dependent_restitution",)


@dataclass(frozen=True)
class CandidateSpec:
    """How to make one candidate effect: its registered ``name`` and construction options."""

    name: str
    options: tuple[tuple[str, Any], ...] = ()

    def make(self) -> Effect:
        from physbench.components import create

        return create("effect", self.name, dict(self.options))  # type: ignore[no-any-return]

    @property
    def label(self) -> str:
        return dict(self.options).get("label", self.name)


def _order(names: Sequence[str]) -> list[str]:
    from physbench.effects import BUILTIN_EFFECTS

    builtin = [c.name for c in BUILTIN_EFFECTS]
    return [n for n in builtin if n in names] + sorted(n for n in names if n not in builtin)


def free_bodies(scene: Scene) -> list[str]:
    jointed = {j.a for j in scene.joints} | {j.b for j in scene.joints if j.b is not None}
    return [b.name for b in scene.bodies if b.name not in jointed]


def candidates_for(
    scene: Scene,
    names: Sequence[str] | None = None,
    *,
    factories: dict[str, Callable[..., Effect]] | None = None,
) -> tuple[list[CandidateSpec], list[tuple[str, str]]]:
    """Candidates for ``scene`` from the registered effects (or ``names``), and the ones left out
    with the reason. Raises :class:`UnknownNameError` for a name that is not registered."""
    from physbench.components import create
    from physbench.plugins import get_registry

    registry = get_registry()
    known = registry.names("effect")
    chosen = _order(known) if names is None else list(dict.fromkeys(names))
    for n in chosen:
        if n not in known:
            raise UnknownNameError("effect", n, known)
    free = free_bodies(scene)
    out: list[CandidateSpec] = []
    skipped: list[tuple[str, str]] = []
    top_down = tuple(scene.gravity) == (0.0, 0.0)
    one_mass = len({b.mass for b in scene.bodies}) == 1
    same = {"constant_force": "table_tilt", "table_tilt": "constant_force"}
    for name in chosen:
        options: dict[str, Any] = {}
        if name == "rolling_resistance" and not top_down and not scene.statics:
            skipped.append(
                (
                    name,
                    "no surface to roll on (gravity acts in the scene's plane and there is no "
                    "static geometry)",
                )
            )
            continue
        if (
            name in same
            and one_mass
            and same[name] in chosen
            and name != ("table_tilt" if top_down else "constant_force")
        ):
            skipped.append((name, f"on bodies of one mass it is {same[name]} again"))
            continue
        if name == "clock_scale" and not scene.forces:
            skipped.append(
                (
                    name,
                    "no force of known size: a clock error would be a change of gravity and "
                    "initial speeds",
                )
            )
            continue
        if name in TRANSLATIONAL_LOSSES and len(free) < len(scene.bodies):
            if not free:
                skipped.append(
                    (name, "no free bodies (on a jointed body this loss is joint damping)")
                )
                continue
            options["bodies"] = free
        if name in CONTACT_LAWS and not scene.statics and len(scene.bodies) < 2:
            skipped.append((name, "nothing to collide with"))
            continue
        spec = CandidateSpec(name, tuple(sorted(options.items())))
        try:
            factory = (factories or {}).get(name)
            eff = factory(**options) if factory else create("effect", name, options)
            eff.setup(scene, {})
        except Exception as exc:  # an effect that cannot describe this scene is not a candidate
            skipped.append((name, _reason(name, exc)))
            continue
        out.append(spec)
    return out, skipped


def _reason(name: str, exc: Exception) -> str:
    """Why effect ``name`` is no candidate, in words: the sentence of physbench's own error
    (without the effect's name, which the list already shows); for any other exception (a
    plugin's bug) also its type, which is all a traceback-less line can tell about it."""
    if isinstance(exc, PhysbenchError):
        return str(exc).removeprefix(f"effect {name!r} ")
    return f"it could not be set up on this scene ({type(exc).__name__}: {exc})"


def start_values(effect: Effect, scene: Scene) -> dict[str, float]:
    """Parameter values at which ``effect`` leaves ``scene``'s dynamics unchanged, where they
    differ from the defaults: a velocity-dependent restitution starts at the scene's typical
    restitution (median product of the surfaces that can meet) and no speed dependence."""
    from physbench.effects.contact import VelocityDependentRestitution

    if isinstance(effect, VelocityDependentRestitution):
        products = [b.elasticity * s.elasticity for b in scene.bodies for s in scene.statics]
        if not effect.statics_only:
            bs = scene.bodies
            products += [
                bs[i].elasticity * bs[j].elasticity
                for i in range(len(bs))
                for j in range(i + 1, len(bs))
            ]
        return {"e0": float(statistics.median(products)) if products else 0.9, "k": 0.0}
    return {}
