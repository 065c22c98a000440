"""The candidate model extensions for a scene: which registered effects apply and to which bodies,
and where their parameters start (where the effect changes nothing, so that a candidate fit starts
from the current model).

Physical effects and measurement causes (effects that
:attr:`~physbench.effects.base.Effect.measures`: a sensor's offset, its clock, the camera's
calibration, axes, lens and plane) are candidates alike.

Rules for the built-ins: translational losses (``linear_drag``, ``quadratic_drag``,
``rolling_resistance``) act on free bodies only: on a body hanging from a pivot they are the joint
losses again (for one arm, drag on the centre of mass *is* viscous or quadratic joint damping and
rolling resistance *is* Coulomb friction), which the joint effects describe. Contact laws need
static geometry or a second body. ``rolling_resistance`` needs a surface to roll on: a top-down
scene (gravity 0) or static geometry; a ball falling through air has none. On bodies that all
have one mass, ``constant_force`` and ``table_tilt`` are the same uniform acceleration: only one
is offered (``table_tilt`` seen from above, ``constant_force`` in a side view, where it is a
change of gravity). The camera's errors (:data:`CAMERA`) need positions in the data (an encoder's
angle has no scale); ``lens_distortion`` and ``plane_tilt`` are centred on the tracked positions'
extent (what the camera framed). A measurement cause that a reference fixes
(:data:`REFERENCES`, ``Settings.references``) is not offered. Any other effect (third-party ones
included) is a candidate when its ``setup`` accepts the scene.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from physbench.errors import PhysbenchError, UnknownNameError

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.recording import Recording
    from physbench.scene import Scene

#: Effects that act on a body's translation like a loss; offered for free bodies only.
TRANSLATIONAL_LOSSES = ("linear_drag", "quadratic_drag", "rolling_resistance")
CONTACT_LAWS = ("velocity_dependent_restitution",)
#: Measurement causes of a camera's view of the plane: they need tracked positions.
CAMERA = ("calibration_scale", "axis_rotation", "lens_distortion", "plane_tilt")
#: Measurement causes centred on the view (options ``centre`` and ``radius``).
VIEW_CENTRED = ("lens_distortion", "plane_tilt")
#: The camera's errors that act in two dimensions: with one coordinate tracked (a drop in y) they
#: would mix the simulated, unmeasured one into it.
PLANAR = ("axis_rotation", "lens_distortion", "plane_tilt")
#: What a reference in the setup fixes (the names ``Settings.references`` takes): the measurement
#: cause it rules out, and the reference in words (also what would tell that cause apart).
REFERENCES: dict[str, tuple[str, str]] = {
    "scale": ("calibration_scale", "a reference length in the plane of motion"),
    "clock": ("clock_scale", "a known frame rate (or a clock in view)"),
    "axes": ("axis_rotation", "a plumb line or a level in view (the true vertical)"),
    "origin": ("sensor_offset", "a fixed point of known position in view"),
    "lens": ("lens_distortion", "a lens calibration (a straight line across the view)"),
    "plane": (
        "plane_tilt",
        "a second view, or a square of known size in the plane (is the plane square to the "
        "camera?)",
    ),
}


def is_measurement(name: str) -> bool:
    """Whether the registered effect ``name`` is a measurement cause (it :attr:`~physbench.effects.
    base.Effect.measures` and applies no forces): it changes what the sensor reports, not the
    motion."""
    from physbench.errors import UnknownNameError
    from physbench.plugins import get_registry

    try:
        cls = get_registry().get("effect", name)
    except UnknownNameError:
        return False
    return bool(cls.measures and not cls.applies_forces and not cls.changes_contacts)


def fixed_by(references: Sequence[str]) -> dict[str, str]:
    """Measurement cause -> the reference that fixes it, for ``references`` (names of
    :data:`REFERENCES`)."""
    return {REFERENCES[r][0]: REFERENCES[r][1] for r in references}


def _planar(recordings: Sequence[Recording] | None) -> bool:
    """Whether every recording tracks both x and y (None: frames, which show the plane)."""
    return recordings is None or all({"x", "y"} <= set(r.fields or ("x", "y")) for r in recordings)


def camera_view(
    recordings: Sequence[Recording],
) -> tuple[tuple[float, float], float] | None:
    """The middle and half diagonal (m) of the box the tracked positions of ``recordings`` span
    (what the camera framed), or None when they hold no positions (a coordinate that was not
    measured, such as x of a ball tracked in y only, spans what its filler spans)."""
    xs: list[float] = []
    ys: list[float] = []
    for rec in recordings:
        if not {"x", "y"} & set(rec.fields or ("x", "y")):
            continue
        for tr in rec.tracks.values():
            xs += [float(tr.x.min()), float(tr.x.max())]
            ys += [float(tr.y.min()), float(tr.y.max())]
    if not xs:
        return None
    centre = ((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2)
    radius = math.hypot(max(xs) - min(xs), max(ys) - min(ys)) / 2
    return centre, max(radius, 1e-3)


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
    recordings: Sequence[Recording] | None = None,
    references: Sequence[str] = (),
) -> tuple[list[CandidateSpec], list[tuple[str, str]]]:
    """Candidates for ``scene`` from the registered effects (or ``names``), and the ones left out
    with the reason. ``recordings``: the data (their fields and extent; None: positions in the
    scene's bounds, as frames show them); ``references``: what the setup fixes
    (:data:`REFERENCES`). Raises :class:`UnknownNameError` for a name that is not registered."""
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
    fixed = fixed_by(references)
    view = camera_view(recordings) if recordings is not None else None
    positions = recordings is None or view is not None
    planar = _planar(recordings)
    for name in chosen:
        options: dict[str, Any] = {}
        if name in fixed:
            skipped.append((name, f"fixed by a reference: {fixed[name]}"))
            continue
        if name in CAMERA and not positions:
            skipped.append(
                (name, "the data hold no positions: a camera's calibration does not enter")
            )
            continue
        if name in PLANAR and not planar:
            skipped.append((name, "it acts in the plane, and the data track one coordinate"))
            continue
        if name in VIEW_CENTRED and view is not None:
            options.update(centre=view[0], radius=view[1])
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
