"""The effect kit: checks of an :class:`~physbench.effects.base.Effect` on a probe scene chosen by
its traits, in the built-in engines (a few ms per simulation).

Probe scenes (1 s at 30 fps, 10 substeps): ``kit_joints`` for an effect whose
:attr:`~physbench.effects.base.Effect.scene_needs` names ``joints`` (a pendulum pinned to the
world, and a disc and a rod pinned to each other, spinning in free fall); ``kit_contacts`` for one
that :attr:`~physbench.effects.base.Effect.changes_contacts` or needs ``contacts`` (a frictionless
table seen from above: a heavy ball hits a light one, which bounces off a cushion, every impact
faster than Box2D's 1 m/s inelastic threshold); ``kit_free`` otherwise (a ball and a spinning box
thrown in gravity, never touching).

"On" values: each parameter halfway from its neutral value (its default when the effect has none)
to the farther end of its range, unless the kit setting ``on_values`` gives them.

The engines agree with an effect on within :data:`AGREEMENT`, poses (m, rad) and velocities (m/s,
rad/s) per probe scene: 10 times or more the largest difference measured with the built-in effects
at their "on" values or without effects (pose / velocity: free 3.5e-5 / 1.7e-5, joints 5.1e-4 /
2.4e-3, contacts 1.4e-4 / 8.9e-5).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any

import numpy as np

from physbench.effects import apply_measurements
from physbench.effects.base import SCENE_FEATURES, Effect
from physbench.errors import PhysbenchError
from physbench.parameter import Parameter
from physbench.scene import Body, Box, Circle, Joint, Scene, Segment
from physbench.simulators.base import Simulator
from physbench.testing.kit import (
    Check,
    ConformanceError,
    Subject,
    construct,
    label,
    require_contract,
    run_checks,
)
from physbench.trajectory import STATE_FIELDS, Trajectory

#: Largest pose and velocity difference between the built-in engines with an effect on, per probe
#: scene.
AGREEMENT: dict[str, tuple[float, float]] = {
    "kit_free": (1e-3, 1e-2),
    "kit_joints": (5e-3, 2.5e-2),
    "kit_contacts": (2e-3, 1e-2),
}
#: Largest difference (any state, or time) between a run at neutral values and one without.
NEUTRAL_TOL = 1e-9
#: The label the kit gives an instance when it checks values passed through ``simulate``.
KIT_LABEL = "kit_effect"


# --------------------------------------------------------------------------- probe scenes


def _rod_centre(pivot: tuple[float, float], length: float, angle: float) -> tuple[float, float]:
    return (pivot[0] + 0.5 * length * math.sin(angle), pivot[1] - 0.5 * length * math.cos(angle))


def free_scene() -> Scene:
    bodies = (
        Body("ball", Circle(0.2), (1.0, 3.0), velocity=(0.5, 2.0), angular_velocity=2.0),
        Body(
            "box",
            Box(0.4, 0.3),
            (3.0, 3.0),
            velocity=(0.5, 2.0),
            angular_velocity=-1.0,
            mass=2.0,
        ),
    )
    return Scene("kit_free", bodies, frames=31).validate()


def joints_scene() -> Scene:
    pivot, angle = (1.0, 3.5), 0.5
    bodies = (
        Body("arm", Box(0.05, 0.8), _rod_centre(pivot, 0.8, angle), angle=angle),
        Body("disc", Circle(0.15), (3.0, 3.0), angular_velocity=3.0),
        Body("rod", Box(0.05, 0.6), (3.0, 2.7), angular_velocity=-3.0, mass=0.5),
    )
    joints = (Joint("arm", pivot), Joint("rod", (3.0, 3.0), "disc"))
    return Scene("kit_joints", bodies, frames=31, joints=joints).validate()


def contacts_scene() -> Scene:
    # Frictionless: friction at impacts spins the balls, which the engines resolve differently.
    ball = {"elasticity": 0.9, "friction": 0.0}
    bodies = (
        Body("cue", Circle(0.15), (0.8, 2.0), velocity=(4.0, 0.4), mass=2.0, **ball),
        Body("target", Circle(0.15), (2.0, 2.0), **ball),
    )
    cushions = (
        Segment((3.6, 0.0), (3.6, 4.0), elasticity=1.0, friction=0.0),
        Segment((0.4, 0.0), (0.4, 4.0), elasticity=1.0, friction=0.0),
    )
    return Scene("kit_contacts", bodies, gravity=(0.0, 0.0), frames=31, statics=cushions).validate()


def probe_scene(cls: type[Effect]) -> Scene:
    """The probe scene for effect class ``cls`` (see the module docstring)."""
    needs = set(cls.scene_needs)
    if "joints" in needs:
        return joints_scene()
    if "contacts" in needs or cls.changes_contacts:
        return contacts_scene()
    return free_scene()


# --------------------------------------------------------------------------- helpers


def active_values(cls: type[Effect], given: Mapping[str, float] | None = None) -> dict[str, float]:
    """``given``, else each parameter halfway from its neutral value to its farther bound."""
    if given is not None:
        return dict(given)
    neutral = cls.neutral() or {}
    out = {}
    for p in cls.params:
        n = float(neutral.get(p.name, p.default if p.default is not None else p.low))
        far = p.high if abs(p.high - n) >= abs(p.low - n) else p.low
        out[p.name] = n + 0.5 * (far - n)
    return out


def _build(cls: type, options: Mapping[str, Any], **values: Any) -> Effect:
    eff: Effect = construct(cls, {**options, **values}, Effect)
    return eff


def _engines() -> list[Simulator]:
    from physbench.simulators.box2d_sim import Box2DSimulator
    from physbench.simulators.pymunk_sim import PymunkSimulator

    return [PymunkSimulator(), Box2DSimulator()]


def _run(
    cls: type[Effect],
    sim: Simulator,
    scene: Scene,
    effects: Sequence[Effect],
    params: Mapping[str, float] | None = None,
) -> Trajectory:
    """The trajectory as measured: simulated with ``effects``, then their ``measure``."""
    try:
        return apply_measurements(sim.simulate(scene, params, effects=effects), effects)
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: simulating the probe scene {scene.name!r} in {sim.name} with "
            f"{list(effects)!r} raised {type(exc).__name__}: {exc}{_needs_hint(cls)}"
        ) from exc


def _needs_hint(cls: type[Effect]) -> str:
    if cls.scene_needs:
        return ""
    return (
        "; if the effect needs something the probe scene lacks, declare it in scene_needs "
        f"(one of {', '.join(SCENE_FEATURES)})"
    )


def _difference(a: Trajectory, b: Trajectory) -> tuple[float, float, str]:
    """Largest pose and velocity difference between ``a`` and ``b`` and where the larger lies."""
    if a.states.shape != b.states.shape:
        return math.inf, math.inf, f"states {a.states.shape} vs {b.states.shape}"
    d = np.abs(a.states - b.states)
    d = np.where(np.isfinite(d), d, np.inf)
    t, i, f = np.unravel_index(int(np.argmax(d)), d.shape)
    where = f"frame {t}, body {a.bodies[i]!r}, {STATE_FIELDS[f]}: {float(a.states[t, i, f])!r} vs "
    where += f"{float(b.states[t, i, f])!r}"
    dt = float(np.abs(a.times - b.times).max()) if a.times.shape == b.times.shape else math.inf
    if dt > d.max():
        where = f"times differ by up to {dt:.3g} s"
    return max(float(d[:, :, :3].max()), dt), float(d[:, :, 3:].max()), where


def _p(cls: type[Effect]) -> tuple[Parameter, ...]:
    return tuple(cls.params)


# --------------------------------------------------------------------------- checks


def check_protocol(cls: type[Effect], **options: Any) -> None:
    """``name`` is a non-empty string, ``params`` a tuple of
    :class:`~physbench.parameter.Parameter` with distinct names, the traits are bools,
    ``scene_needs`` names known features, ``neutral()`` is ``None`` or a value in range for every
    parameter, and ``cls(**options)`` builds an Effect whose ``parameters()`` are keyed by its
    ``key``."""
    require_contract(cls, Effect)
    params = cls.params
    if not isinstance(params, tuple) or not all(isinstance(p, Parameter) for p in params):
        raise ConformanceError(
            f"{label(cls)}: class attribute 'params' must be a tuple of "
            f"physbench.parameter.Parameter, got {params!r}"
        )
    names = [p.name for p in params]
    if len(set(names)) != len(names):
        raise ConformanceError(f"{label(cls)}: parameter names repeat: {names}")
    traits = {
        "applies_forces": cls.applies_forces,
        "changes_contacts": cls.changes_contacts,
        "measures": cls.measures,
    }
    for trait, value in traits.items():
        if not isinstance(value, bool):
            raise ConformanceError(
                f"{label(cls)}: trait {trait!r} must be True or False, got {value!r}"
            )
    needs = cls.scene_needs
    if not isinstance(needs, tuple) or not set(needs) <= set(SCENE_FEATURES):
        raise ConformanceError(
            f"{label(cls)}: scene_needs = {needs!r}: expected a tuple of "
            f"{', '.join(SCENE_FEATURES)}"
        )
    eff = _build(cls, options)
    keys = [p.key for p in eff.parameters()]
    if keys != [f"{eff.key}.{n}" for n in names]:
        raise ConformanceError(
            f"{label(cls)}: parameters() are keyed {keys}; expected '<key>.<param>' with key "
            f"{eff.key!r}"
        )
    neutral = cls.neutral()
    if neutral is not None:
        by_name = {p.name: p for p in params}
        if set(neutral) != set(names) or not all(
            by_name[k].contains(v) for k, v in neutral.items()
        ):
            raise ConformanceError(
                f"{label(cls)}: neutral() = {neutral!r}: expected None or a value inside the "
                f"range of each of {names}"
            )


def check_defaults_in_range(cls: type[Effect], **options: Any) -> None:
    """Every declared parameter has a finite range ``low < high`` and a default inside it."""
    for p in _p(cls):
        if not (math.isfinite(p.low) and math.isfinite(p.high) and p.low < p.high):
            raise ConformanceError(
                f"{label(cls)}: parameter {p.name!r} has range [{p.low}, {p.high}]; expected "
                "finite bounds, low < high"
            )
        if p.default is None or not p.contains(p.default):
            raise ConformanceError(
                f"{label(cls)}: parameter {p.name!r} has default {p.default!r}, outside its "
                f"range {p.describe()}"
            )


def _refused(cls: type, what: str, name: str, run: Callable[..., object], *args: Any) -> None:
    """``run(*args)`` must raise an error naming ``name``."""
    try:
        run(*args)
    except ConformanceError as exc:  # from _run: judge the simulator's error it carries
        cause = exc.__cause__
        if not isinstance(cause, PhysbenchError | ValueError) or name not in str(cause):
            raise
    except (PhysbenchError, ValueError) as exc:
        if name not in str(exc):
            raise ConformanceError(
                f"{label(cls)}: {what} raised {type(exc).__name__} without naming {name!r}: {exc}"
            ) from exc
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: {what} raised {type(exc).__name__}: {exc}; raise "
            f"physbench.effects.base.EffectError naming {name!r}"
        ) from exc
    else:
        raise ConformanceError(f"{label(cls)}: {what} was accepted")


def check_rejects_out_of_range(cls: type[Effect], **options: Any) -> None:
    """A value outside a parameter's range (or NaN) is refused with an error naming the
    parameter: at construction, in ``setup`` and through ``simulate(params=...)``."""
    scene = probe_scene(cls)
    sim = _engines()[0]
    for p in _p(cls):
        span = p.high - p.low
        for bad in (p.high + span, p.low - span, math.nan):
            kw = {**options, p.name: bad}
            _refused(cls, f"{cls.__name__}(**{kw!r})", p.name, lambda kw: cls(**kw), kw)
            eff = _build(cls, options)
            values = {f"{eff.key}.{p.name}": bad}
            _refused(cls, f"setup(scene, {values})", p.name, eff.setup, scene, values)
            what = f"simulate(scene, {values}, effects=[...])"
            _refused(cls, what, p.name, _run, cls, sim, scene, [eff], values)


def check_neutral(cls: type[Effect], **options: Any) -> None:
    """At its :meth:`~physbench.effects.base.Effect.neutral` values the effect changes nothing:
    the measured trajectory of the probe scene equals the one without it (within 1e-9)."""
    neutral = cls.neutral()
    if neutral is None:
        return
    scene = probe_scene(cls)
    sim = _engines()[0]
    plain = _run(cls, sim, scene, [])
    eff = _build(cls, options, **neutral)
    with_it = _run(cls, sim, scene, [eff])
    dp, dv, where = _difference(with_it, plain)
    if max(dp, dv) > NEUTRAL_TOL:
        raise ConformanceError(
            f"{label(cls)}: at its neutral values {neutral} the effect changes the probe scene "
            f"{scene.name!r} ({where}); zero magnitude must mean no effect, or override "
            "neutral() when the defaults are not neutral"
        )


def check_traits(
    cls: type[Effect], *, on_values: Mapping[str, float] | None = None, **options: Any
) -> None:
    """The declared traits match what the effect does at its "on" values on the probe scene's
    states: ``applies_forces = False`` -> zero forces and torques; ``changes_contacts = False``
    -> ``restitution`` returns ``None``; ``measures = False`` -> ``measure`` returns the
    trajectory unchanged."""
    scene = probe_scene(cls)
    values = active_values(cls, on_values)
    traj = _run(cls, _engines()[0], scene, [])
    eff = _build(cls, options, **values)
    try:
        eff.setup(scene, {})
    except Exception as exc:
        raise ConformanceError(
            f"{label(cls)}: setup() on the probe scene {scene.name!r} raised "
            f"{type(exc).__name__}: {exc}{_needs_hint(cls)}"
        ) from exc
    if not cls.applies_forces:
        for k in range(traj.frames):
            f, tau = eff.forces(float(traj.times[k]), traj.states[k].copy())
            if np.any(np.asarray(f) != 0) or np.any(np.asarray(tau) != 0):
                raise ConformanceError(
                    f"{label(cls)}: declares applies_forces = False, but forces() at {values} "
                    f"returns forces {np.asarray(f).tolist()} and torques "
                    f"{np.asarray(tau).tolist()} at frame {k}; the engines never call it, so "
                    "set applies_forces = True"
                )
    if not cls.changes_contacts:
        n = len(scene.bodies)
        for speed in (0.5, 2.0, 5.0):
            for a, b in ((0, None), (0, 1 % n)):
                e = eff.restitution(speed, a, b)
                if e is not None:
                    raise ConformanceError(
                        f"{label(cls)}: declares changes_contacts = False, but "
                        f"restitution({speed}, {a}, {b}) returns {e!r}; the engines never ask "
                        "it, so set changes_contacts = True"
                    )
    if not cls.measures:
        seen = eff.measure(traj)
        dp, dv, where = _difference(seen, traj)
        if max(dp, dv) > 0:
            raise ConformanceError(
                f"{label(cls)}: declares measures = False, but measure() changes the trajectory "
                f"({where}); the framework never calls it, so set measures = True"
            )


def check_acts(
    cls: type[Effect], *, on_values: Mapping[str, float] | None = None, **options: Any
) -> None:
    """At its "on" values the effect changes the measured trajectory of its probe scene (else it
    is inert, or acts through a path its traits do not declare)."""
    scene = probe_scene(cls)
    values = active_values(cls, on_values)
    sim = _engines()[0]
    dp, dv, _ = _difference(
        _run(cls, sim, scene, [_build(cls, options, **values)]), _run(cls, sim, scene, [])
    )
    if max(dp, dv) <= NEUTRAL_TOL:
        raise ConformanceError(
            f"{label(cls)}: at {values} the effect changes nothing on the probe scene "
            f"{scene.name!r}; check its traits (applies_forces, changes_contacts, measures) and "
            "scene_needs"
        )


def check_values_from_params(
    cls: type[Effect], *, on_values: Mapping[str, float] | None = None, **options: Any
) -> None:
    """Values given through ``simulate(params={"<label>.<param>": v})`` to an instance built with
    ``label=...`` act exactly as the same values given at construction (the simulator passes them
    to ``setup``, which must override the constructor's)."""
    scene = probe_scene(cls)
    values = active_values(cls, on_values)
    sim = _engines()[0]
    direct = _run(cls, sim, scene, [_build(cls, options, **values)])
    opts = {**options, "label": KIT_LABEL}
    params = {f"{KIT_LABEL}.{k}": v for k, v in values.items()}
    routed = _run(cls, sim, scene, [_build(cls, opts)], params)
    dp, dv, where = _difference(routed, direct)
    if max(dp, dv) > 0:
        raise ConformanceError(
            f"{label(cls)}: values {params} passed through simulate(params=...) act "
            f"differently from the same values given to the constructor ({where}); compute "
            "from self.values in configure() or later, not in __init__"
        )


def check_engines_agree(
    cls: type[Effect], *, on_values: Mapping[str, float] | None = None, **options: Any
) -> None:
    """The built-in engines (pymunk, Box2D) agree on the probe scene with the effect on, within
    :data:`AGREEMENT`, one instance serving both runs (state must not leak between
    simulations)."""
    scene = probe_scene(cls)
    values = active_values(cls, on_values)
    eff = _build(cls, options, **values)
    a, b = (_run(cls, sim, scene, [eff]) for sim in _engines())
    dp, dv, where = _difference(a, b)
    pose_tol, vel_tol = AGREEMENT[scene.name]
    if not (dp <= pose_tol and dv <= vel_tol):
        raise ConformanceError(
            f"{label(cls)}: with {values} pymunk and Box2D disagree on the probe scene "
            f"{scene.name!r} by {dp:.3g} in pose and {dv:.3g} in velocity (allowed {pose_tol:g} "
            f"and {vel_tol:g}; largest at {where}); the effect must act the same in every engine "
            "and keep no state from one simulation to the next"
        )


#: Kit settings the effect checks take.
SETTINGS = frozenset({"on_values"})
#: Every effect check, in the order they run.
CHECKS = (
    check_protocol,
    check_defaults_in_range,
    check_rejects_out_of_range,
    check_neutral,
    check_traits,
    check_acts,
    check_values_from_params,
    check_engines_agree,
)


def yield_checks(subject: Subject) -> Iterator[Any]:
    """The effect checks for ``subject``: ``check_neutral`` only when it has neutral values, the
    value checks only when it has parameters."""
    cls = subject.cls
    if not (isinstance(cls, type) and issubclass(cls, Effect)):
        yield from CHECKS  # the protocol check says why, and the kit stops there
        return
    for check in CHECKS:
        if check is check_neutral and cls.neutral() is None:
            continue
        if check in (check_rejects_out_of_range, check_values_from_params) and not _p(cls):
            continue
        yield check


def check_effect(
    cls: type[Effect], /, *, on_values: Mapping[str, float] | None = None, **options: Any
) -> None:
    """Every effect check that applies to ``cls(**options)``; raises one
    :class:`ConformanceError` listing every failure."""
    subject = Subject(cls, options, {} if on_values is None else {"on_values": on_values})
    checks = [Check(f) for f in yield_checks(subject)]
    run_checks(subject, checks, stop_after=check_protocol.__name__)
