"""Synthetic recordings with a hidden effect, for testing and calibrating discovery.

:func:`make_case` builds one of a few cheap scenes (seeded), simulates it with a hidden effect at a
random magnitude (or none, for a control), adds Gaussian tracking noise, and returns the run
together with the truth. Each scene is chosen so that the effects listed for it are identifiable
from its data: a constant force needs bodies of different masses to differ from a table tilt, a
clock error needs a force of known size (a kick) to differ from a change of gravity, a sensor
offset needs something fixed in the world (a pivot, a floor) to differ from the initial position.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from physbench.discover.candidates import VIEW_CENTRED, camera_view, is_measurement
from physbench.discover.data import Run
from physbench.recording import Recording, Track
from physbench.scene import Body, Box, Circle, Force, Joint, Scene, Segment, body_unknown
from physbench.trajectory import Trajectory

G = 9.81
#: Tracking noise: positions (m) and angles (rad); balls bouncing at several m/s are tracked less
#: precisely (motion blur over a frame is centimetres).
NOISE_POS, NOISE_ANGLE, NOISE_IMPACTS = 0.002, 0.003, 0.005
IMPACT_SCENES = ("bouncer", "drops")


@dataclass(frozen=True)
class SyntheticRun:
    """A synthetic run and what is hidden in it (``effect`` None for a control)."""

    name: str
    scene_kind: str
    run: Run
    effect: str | None
    truth: dict[str, float] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)
    #: What the bodies really did (the effect's measurement included), before tracking noise: what
    #: a camera filming the run would see.
    trajectory: Trajectory | None = None
    #: Measurement errors of the recording on top of the hidden effect (``make_case``'s
    #: ``distortion``): ``{effect name: values}``.
    distortion: dict[str, dict[str, float]] = field(default_factory=dict)


def _rng(seed: int, salt: int) -> np.random.Generator:
    return np.random.default_rng([int(seed), int(salt)])


def _sign(rng: np.random.Generator) -> float:
    return 1.0 if rng.random() < 0.5 else -1.0


# --------------------------------------------------------------------------- scenes


def projectile(rng: np.random.Generator, kick: bool = False) -> Scene:
    """A ball thrown in a side view, optionally kicked mid-flight by a known force."""
    m = float(rng.uniform(0.5, 2.0))
    v = (float(rng.uniform(2.5, 3.5)), float(rng.uniform(3.0, 5.0)))
    forces: tuple[Force, ...] = ()
    if kick:
        t0 = float(rng.uniform(0.7, 0.9))
        forces = (
            Force(
                "ball",
                (m * float(rng.uniform(-25, -15)), m * float(rng.uniform(5, 15))),
                t0,
                t0 + 0.1,
            ),
        )
    return Scene(
        "projectile" + ("_kicked" if kick else ""),
        (Body("ball", Circle(0.05), (0.5, 1.0), velocity=v, mass=m),),
        bounds=(-2.0, -12.0, 10.0, 8.0),
        fps=20.0,
        frames=41,
        substeps=4,
        forces=forces,
    )


def puck(rng: np.random.Generator, kicks: bool = False) -> Scene:
    """A puck sliding on a table seen from above (gravity 0), optionally kicked twice."""
    m = float(rng.uniform(0.2, 1.0))
    v = (float(rng.uniform(1.5, 2.5)), float(rng.uniform(-0.3, 0.3)))
    forces: tuple[Force, ...] = ()
    if kicks:
        t1, t2 = float(rng.uniform(0.6, 0.9)), float(rng.uniform(1.5, 1.8))
        forces = (
            Force("puck", (0.0, m * float(rng.uniform(10, 20))), t1, t1 + 0.1),
            Force("puck", (-m * float(rng.uniform(10, 15)), 0.0), t2, t2 + 0.1),
        )
    return Scene(
        "puck" + ("_kicked" if kicks else ""),
        (Body("puck", Circle(0.05), (0.5, 2.0), velocity=v, mass=m),),
        bounds=(-2.0, -2.0, 8.0, 6.0),
        gravity=(0.0, 0.0),
        fps=20.0,
        frames=51,
        substeps=4,
        forces=forces,
    )


def pucks(rng: np.random.Generator, slow: bool = False) -> Scene:
    """Pucks on a table seen from above: two sliding in different directions, or one slow puck
    that comes to rest within the recording (a constant deceleration then differs from a tilt)."""
    if slow:
        v = float(rng.uniform(0.5, 0.8))
        ang = float(rng.uniform(-0.5, 0.5))
        bodies = (
            Body(
                "puck",
                Circle(0.05),
                (1.0, 2.0),
                velocity=(v * math.cos(ang), v * math.sin(ang)),
                mass=float(rng.uniform(0.2, 1.0)),
            ),
        )
    else:
        a1 = float(rng.uniform(-0.4, 0.4))
        a2 = a1 + float(rng.uniform(1.8, 2.6))
        s1, s2 = float(rng.uniform(1.0, 1.6)), float(rng.uniform(1.0, 1.6))
        bodies = (
            Body(
                "a",
                Circle(0.05),
                (3.0, 2.0),
                velocity=(s1 * math.cos(a1), s1 * math.sin(a1)),
                mass=float(rng.uniform(0.2, 1.0)),
            ),
            Body(
                "b",
                Circle(0.05),
                (2.0, 3.0),
                velocity=(s2 * math.cos(a2), s2 * math.sin(a2)),
                mass=float(rng.uniform(0.2, 1.0)),
            ),
        )
    return Scene(
        "puck_slow" if slow else "pucks",
        bodies,
        bounds=(-2.0, -2.0, 8.0, 7.0),
        gravity=(0.0, 0.0),
        fps=20.0,
        frames=51,
        substeps=4,
    )


def two_bodies(rng: np.random.Generator, gravity: bool) -> Scene:
    """Two free balls of quite different masses (side view with gravity, or top-down)."""
    m1, m2 = float(rng.uniform(0.3, 0.6)), float(rng.uniform(1.5, 3.0))
    vy = (3.0, 2.0) if gravity else (0.4, -0.4)
    a = Body(
        "light",
        Circle(0.05),
        (1.0, 2.0),
        velocity=(float(rng.uniform(1.0, 2.0)), vy[0] + float(rng.uniform(-0.5, 0.5))),
        mass=m1,
    )
    b = Body(
        "heavy",
        Circle(0.08),
        (1.0, 3.5),
        velocity=(float(rng.uniform(1.0, 2.0)), vy[1] + float(rng.uniform(-0.5, 0.5))),
        mass=m2,
    )
    return Scene(
        "two_projectiles" if gravity else "two_pucks",
        (a, b),
        bounds=(-3.0, -10.0, 9.0, 8.0),
        gravity=(0.0, -G) if gravity else (0.0, 0.0),
        fps=20.0,
        frames=41,
        substeps=4,
    )


def pendulum(
    rng: np.random.Generator, amplitude: tuple[float, float] = (0.6, 1.0), tracked: str = ""
) -> Scene:
    """A rigid arm on a pivot, released from rest; ``tracked`` names the recording ("": encoder
    angle, "_xy": camera position, "_both": both)."""
    length, m = float(rng.uniform(0.3, 0.5)), float(rng.uniform(0.3, 1.0))
    theta = _sign(rng) * float(rng.uniform(*amplitude))
    pivot = (1.0, 1.5)
    centre = (pivot[0] + math.sin(theta) * length / 2, pivot[1] - math.cos(theta) * length / 2)
    arm = Body("arm", Box(0.04, length), centre, angle=theta, mass=m, friction=0.0)
    return Scene(
        "pendulum" + tracked,
        (arm,),
        bounds=(0.0, 0.0, 2.0, 2.0),
        fps=20.0,
        frames=81,
        substeps=10,
        joints=(Joint("arm", pivot),),
    )


def double_pendulum(rng: np.random.Generator) -> Scene:
    """Two arms in a chain, small swings."""
    l1, l2 = float(rng.uniform(0.3, 0.4)), float(rng.uniform(0.25, 0.35))
    t1, t2 = _sign(rng) * float(rng.uniform(0.3, 0.5)), _sign(rng) * float(rng.uniform(0.2, 0.4))
    p = np.array([1.0, 1.7])
    u1 = np.array([math.sin(t1), -math.cos(t1)])
    u2 = np.array([math.sin(t2), -math.cos(t2)])
    c1, elbow = p + u1 * l1 / 2, p + u1 * l1
    c2 = elbow + u2 * l2 / 2
    a = Body(
        "upper",
        Box(0.04, l1),
        (float(c1[0]), float(c1[1])),
        angle=t1,
        mass=float(rng.uniform(0.4, 0.8)),
        friction=0.0,
    )
    b = Body(
        "lower",
        Box(0.04, l2),
        (float(c2[0]), float(c2[1])),
        angle=t2,
        mass=float(rng.uniform(0.2, 0.5)),
        friction=0.0,
    )
    return Scene(
        "double_pendulum",
        (a, b),
        bounds=(0.0, 0.0, 2.0, 2.0),
        fps=20.0,
        frames=81,
        substeps=10,
        joints=(
            Joint("upper", (float(p[0]), float(p[1]))),
            Joint("lower", (float(elbow[0]), float(elbow[1])), "upper"),
        ),
    )


def bouncer(rng: np.random.Generator) -> Scene:
    """A ball bouncing in a box seen from the side; its elasticity is a base-model unknown."""
    e = float(rng.uniform(0.75, 0.9))
    ball = Body(
        "ball",
        Circle(0.08),
        (0.6, float(rng.uniform(0.7, 0.9))),
        velocity=(float(rng.uniform(1.5, 2.5)), float(rng.uniform(0.0, 1.0))),
        mass=float(rng.uniform(0.2, 1.0)),
        elasticity=e,
        friction=0.0,
    )
    walls = (
        Segment((0.0, 0.0), (2.0, 0.0)),
        Segment((0.0, 0.0), (0.0, 3.0)),
        Segment((2.0, 0.0), (2.0, 3.0)),
    )
    walls = tuple(Segment(s.a, s.b, elasticity=1.0, friction=0.0) for s in walls)
    return Scene(
        "bouncer",
        (ball,),
        bounds=(0.0, 0.0, 2.0, 3.0),
        fps=25.0,
        frames=41,
        substeps=20,
        statics=walls,
        unknowns=(body_unknown("ball", "elasticity", 0.3, 1.0),),
    )


def drops(rng: np.random.Generator) -> Scene:
    """Two balls of one material dropped side by side from a low and a high start: their impacts
    span a wide range of speeds (about 5 m/s down to 1.5 m/s), which a single constant
    restitution cannot match."""
    floor = (Segment((-1.0, 0.0), (3.0, 0.0), elasticity=1.0, friction=0.0),)
    low = Body(
        "low",
        Circle(0.06),
        (0.5, float(rng.uniform(0.3, 0.4))),
        velocity=(0.0, -0.3),
        mass=0.2,
        elasticity=0.8,
        friction=0.0,
    )
    high = Body(
        "high",
        Circle(0.06),
        (1.5, float(rng.uniform(1.0, 1.3))),
        velocity=(0.0, -0.3),
        mass=0.2,
        elasticity=0.8,
        friction=0.0,
    )
    return Scene(
        "drops",
        (low, high),
        bounds=(0.0, 0.0, 2.0, 2.0),
        fps=25.0,
        frames=41,
        substeps=20,
        statics=floor,
    )


SCENES = {
    "projectile": lambda r: projectile(r),
    "projectile_kicked": lambda r: projectile(r, kick=True),
    "puck": lambda r: puck(r),
    "puck_kicked": lambda r: puck(r, kicks=True),
    "pucks": lambda r: pucks(r),
    "puck_slow": lambda r: pucks(r, slow=True),
    "two_projectiles": lambda r: two_bodies(r, True),
    "two_pucks": lambda r: two_bodies(r, False),
    "pendulum": lambda r: pendulum(r),
    "pendulum_large": lambda r: pendulum(r, (1.2, 1.5)),
    "pendulum_xy": lambda r: pendulum(r, (0.9, 1.3), tracked="_xy"),
    "pendulum_both": lambda r: pendulum(r, (0.6, 1.0), tracked="_both"),
    "double_pendulum": double_pendulum,
    "bouncer": bouncer,
    "drops": drops,
}

#: Effect -> the scenes its hidden-effect tests use.
EFFECT_SCENES: dict[str, tuple[str, ...]] = {
    "linear_drag": ("projectile", "puck"),
    "quadratic_drag": ("projectile", "puck"),
    "rolling_resistance": ("pucks", "puck_slow"),
    "constant_force": ("two_pucks", "two_projectiles"),
    "table_tilt": ("two_pucks", "two_projectiles"),
    "joint_viscous_damping": ("pendulum", "double_pendulum"),
    "joint_coulomb_friction": ("pendulum", "double_pendulum"),
    "joint_quadratic_damping": ("pendulum_large", "pendulum_xy"),
    "velocity_dependent_restitution": ("bouncer", "drops"),
    "sensor_offset": ("pendulum_xy", "pendulum_both"),
    "clock_scale": ("projectile_kicked", "puck_kicked"),
    "calibration_scale": ("puck_kicked", "pendulum_xy"),
    "axis_rotation": ("projectile_kicked", "pendulum_xy"),
    "lens_distortion": ("projectile", "two_pucks"),
    "plane_tilt": ("projectile", "projectile_kicked"),
}


def hidden_values(effect: str, scene: Scene, rng: np.random.Generator) -> dict[str, float]:
    """A random magnitude of ``effect``, clearly visible in ``scene`` over its duration."""
    masses = np.array([b.mass for b in scene.bodies])
    m = float(masses.mean())
    if effect == "linear_drag":
        return {"c": m * float(rng.uniform(0.2, 0.5))}
    if effect == "quadratic_drag":
        return {"c": m * float(rng.uniform(0.15, 0.3))}
    if effect == "rolling_resistance":
        return {"mu": float(rng.uniform(0.03, 0.06))}
    if effect in ("constant_force", "table_tilt"):
        mag = float(rng.uniform(0.2, 0.5)) * (m if effect == "constant_force" else 1.0)
        ang = float(rng.uniform(0, 2 * math.pi))
        k = ("fx", "fy") if effect == "constant_force" else ("ax", "ay")
        return {k[0]: mag * math.cos(ang), k[1]: mag * math.sin(ang)}
    if effect.startswith("joint_"):
        inertia = sum(
            b.inertia() + b.mass * (b.shape.height / 2) ** 2
            for b in scene.bodies
            if isinstance(b.shape, Box)
        )
        arm = scene.bodies[0]
        assert isinstance(arm.shape, Box)
        mgd = arm.mass * G * arm.shape.height / 2
        if effect == "joint_viscous_damping":
            return {
                "c": inertia * float(rng.uniform(0.15, 0.35))
            }  # amplitude decay rate c / 2I: 0.08-0.18 /s
        if effect == "joint_coulomb_friction":
            return {"tau": mgd * float(rng.uniform(0.01, 0.02))}  # 0.04-0.08 rad lost per cycle
        return {"c": inertia * float(rng.uniform(0.03, 0.06))}
    if effect == "velocity_dependent_restitution":
        return {"e0": float(rng.uniform(0.9, 0.98)), "k": float(rng.uniform(0.08, 0.12))}
    if effect == "sensor_offset":
        out = {
            "dx": _sign(rng) * float(rng.uniform(0.02, 0.05)),
            "dy": _sign(rng) * float(rng.uniform(0.02, 0.05)),
        }
        if scene.name.endswith("_both"):
            out["dangle"] = _sign(rng) * float(rng.uniform(0.04, 0.1))
        return out
    if effect == "clock_scale":
        return {"scale": 1.0 + _sign(rng) * float(rng.uniform(0.05, 0.1))}
    if effect == "calibration_scale":
        return {"scale": 1.0 + _sign(rng) * float(rng.uniform(0.03, 0.08))}
    if effect == "axis_rotation":
        return {"angle": _sign(rng) * float(rng.uniform(0.03, 0.08))}
    if effect == "lens_distortion":
        return {"k1": _sign(rng) * float(rng.uniform(0.05, 0.1))}
    if effect == "plane_tilt":
        mag, ang = float(rng.uniform(0.15, 0.25)), float(rng.uniform(0, 2 * math.pi))
        return {"tx": mag * math.cos(ang), "ty": mag * math.sin(ang)}
    raise KeyError(effect)


def magnitude_error(effect: str, truth: dict[str, float], got: dict[str, float]) -> float:
    """Relative error of the fitted magnitude: of the parameter vector for vector effects (force,
    tilt, offset), of the restitution law over the impact speeds seen (1.5-5 m/s) for the contact
    law, of the single parameter otherwise."""
    if effect == "velocity_dependent_restitution":
        v = np.linspace(1.5, 5.0, 8)
        from physbench.effects import restitution_law

        want = np.asarray(restitution_law(v, truth["e0"], truth["k"]))
        have = np.asarray(restitution_law(v, got["e0"], got["k"]))
        return float(np.max(np.abs(have - want) / want))
    keys = list(truth)
    t = np.array([truth[k] for k in keys])
    g = np.array([got.get(k, math.nan) for k in keys])
    if effect in ("clock_scale", "calibration_scale"):  # the magnitude: the deviation from 1
        t, g = t - 1.0, g - 1.0
    return float(np.linalg.norm(g - t) / np.linalg.norm(t))


def _record(
    scene_kind: str, scene: Scene, traj: Trajectory, t_end: float, rng: np.random.Generator
) -> Recording:
    """Samples at the scene's frame times up to ``t_end`` with tracking noise."""
    times = np.arange(0.0, t_end + 1e-9, 1.0 / scene.fps)
    base = Recording.from_trajectory(traj, times=times)
    sigma = NOISE_IMPACTS if scene_kind in IMPACT_SCENES else NOISE_POS
    tracks = {}
    for b, tr in base.tracks.items():
        n = len(tr)
        angle = None if tr.angle is None else tr.angle + rng.normal(0, NOISE_ANGLE, n)
        tracks[b] = Track(
            tr.t, tr.x + rng.normal(0, sigma, n), tr.y + rng.normal(0, sigma, n), angle
        )
    if scene_kind.endswith("_both"):
        fields: tuple[str, ...] = ("x", "y", "angle")
    elif scene.joints and not scene_kind.endswith("_xy"):
        fields = ("angle",)
    else:
        fields = ("x", "y")
    return Recording(tracks, run=scene_kind, fields=fields, source="synthetic")


def make_case(
    effect: str | None,
    scene_kind: str,
    seed: int,
    engine: Any,
    truth: Mapping[str, float] | None = None,
    body_params: Mapping[str, float] | None = None,
    distortion: Mapping[str, Mapping[str, float]] | None = None,
) -> SyntheticRun:
    """One synthetic run of ``scene_kind`` (see :data:`SCENES`) with ``effect`` hidden at a random
    magnitude (None: a control), simulated by ``engine`` (a simulator instance). ``truth``: the
    hidden values instead (missing ones random), beyond the effect's declared ranges if need be
    (an extensible range is widened to hold them; the random draws are made all the same, so the
    scene and the noise do not change). ``body_params``: body parameters (``{"ball.mass": 80}``)
    applied to the drawn scene, for magnitudes that need a heavier or larger body to stay
    visible without swamping the motion. ``distortion``: measurement errors of the recording on
    top, ``{effect name: values}`` (``{"calibration_scale": {"scale": 0.97}}``), applied after the
    hidden effect; the camera's view is the box the true positions span."""
    rng = _rng(seed, 1 + sorted(SCENES).index(scene_kind))
    scene = SCENES[scene_kind](rng).with_params(body_params or {}).validate()
    values: dict[str, float] = {}
    if effect is not None:
        values = {**hidden_values(effect, scene, rng), **(truth or {})}
    t_end = (scene.frames - 1) / scene.fps
    clocks = [values.get("scale", 1.0)] if effect == "clock_scale" else []
    clocks += [v.get("scale", 1.0) for k, v in (distortion or {}).items() if k == "clock_scale"]
    stretch = max([1.0, *clocks])
    sim_scene = (
        scene if stretch <= 1 else replace(scene, frames=math.ceil(t_end * stretch * scene.fps) + 2)
    )
    errors = dict(distortion or {})
    physical = []
    if effect is not None and is_measurement(effect):
        errors = {effect: values, **errors}
    elif effect is not None:
        physical = [_effect(effect, scene, values)]
    traj = engine.simulate(sim_scene, effects=physical)
    traj = _measured(traj, scene, errors, t_end)
    rec = _record(scene_kind, scene, traj, t_end, rng)
    name = f"{effect or 'control'}/{scene_kind}/{seed}"
    return SyntheticRun(
        name,
        scene_kind,
        Run(name, _blur(scene, rng), recording=rec, source="synthetic"),
        effect,
        values,
        trajectory=traj,
        distortion={k: dict(v) for k, v in (distortion or {}).items()},
    )


def _effect(
    name: str, scene: Scene, values: Mapping[str, float], options: Mapping[str, Any] | None = None
) -> Any:
    """The registered effect ``name`` set up on ``scene`` with ``values``, its extensible ranges
    widened to hold them."""
    from physbench.components import create

    eff = create("effect", name, dict(options or {}))
    for p in eff.parameters():
        wide = p
        while not wide.contains(values.get(p.name, 0.0)) and wide.extensible:
            wide = wide.widened()
        if wide is not p:
            eff.widen(p.name, wide.low, wide.high)
    eff.setup(scene, dict(values))
    return eff


def _measured(
    traj: Trajectory, scene: Scene, errors: Mapping[str, Mapping[str, float]], t_end: float
) -> Trajectory:
    """``traj`` as the sensor reports it, through each measurement effect of ``errors`` in turn.
    Those centred on the camera's view get the box the *reported* positions span up to ``t_end``,
    as discovery gives its candidates the data's (found by iterating: the view moves the
    reported positions a little, which move the view)."""
    from physbench.effects import apply_measurements

    times = traj.times[traj.times <= t_end + 1e-9]

    def view_of(t: Trajectory) -> tuple[tuple[float, float], float] | None:
        return camera_view([Recording.from_trajectory(t, times=times)])

    view, out = view_of(traj), traj
    for _ in range(8 if any(n in VIEW_CENTRED for n in errors) else 1):
        effects = [
            _effect(n, scene, v, {"centre": view[0], "radius": view[1]})
            if n in VIEW_CENTRED and view is not None
            else _effect(n, scene, v)
            for n, v in errors.items()
        ]
        out = apply_measurements(traj, effects)
        seen = view_of(out)
        if seen == view or seen is None or view is None:
            break
        moved = math.hypot(seen[0][0] - view[0][0], seen[0][1] - view[0][1])
        view = seen
        if moved + abs(seen[1] - view[1]) < 1e-9:
            break
    return out


def _blur(scene: Scene, rng: np.random.Generator) -> Scene:
    """The scene as the experimenter knows it: initial state and unknowns slightly off the truth."""
    from physbench.discover.model import apply_initial, chain_parents

    parents = chain_parents(scene) or {}
    state: dict[str, dict[str, float]] = {}
    for b in scene.bodies:
        if b.name in parents:
            state[b.name] = {"angle0": b.angle + float(rng.normal(0, 0.01))}
        elif math.hypot(*b.velocity) > 0:
            state[b.name] = {
                "x0": b.position[0] + float(rng.normal(0, 0.005)),
                "y0": b.position[1] + float(rng.normal(0, 0.005)),
                "vx0": b.velocity[0] * (1 + float(rng.normal(0, 0.03))),
                "vy0": b.velocity[1] * (1 + float(rng.normal(0, 0.03))),
            }
    scene = apply_initial(scene, state, {})
    for u in scene.unknowns:
        b = scene.bodies[scene.body_index(u.owner)]
        guess = float(
            np.clip(getattr(b, u.name) + 0.1 * (u.high - u.low) * _sign(rng), u.low, u.high)
        )
        scene = scene.with_params({u.key: guess})
    return scene


#: How :func:`filmed_run` films a case by default: an oblique camera with motion blur, sensor
#: noise, flickering light and lossy H.264, at 640x480.
FILM = {
    "resolution": 640,
    "tilt": 12.0,
    "shutter": 0.5,
    "subframes": 8,
    "noise": 0.01,
    "flicker": 0.05,
    "bitrate": 2_000_000,
}


def filmed_run(case: SyntheticRun, seed: int = 0, **camera: Any) -> Run:
    """``case``'s run with its recording replaced by what a camera and the tracker make of the
    true motion: filmed by the ``camera`` renderer (options :data:`FILM`, overridden by
    ``camera``; the view frames where the bodies go), encoded, tracked with a four-point
    calibration, keeping the recording's fields
    (:func:`~physbench.video.footage.filmed_recording`)."""
    from physbench.render.camera import CameraRenderer
    from physbench.video.footage import filmed_recording, frame_trajectory, motion_view

    run, rec = case.run, case.run.recording
    if case.trajectory is None or rec is None:
        raise ValueError(f"case {case.name!r} has no true trajectory to film")
    traj = frame_trajectory(case.trajectory, np.arange(run.scene.frames) / run.scene.fps)
    options = {**FILM, "seed": seed, "view": motion_view(run.scene, traj), **camera}
    filmed = filmed_recording(run.scene, traj, CameraRenderer(**options), fields=rec.fields)
    return replace(run, recording=replace(filmed, run=rec.run), source="filmed")


# --------------------------------------------------------------------------- measurement errors

#: Scenes of the measurement benchmark (``benchmarks/discover_measurement.py``): a ball in free
#: flight (side view), and a puck seen from above with two kicks of known size (without them a
#: puck's steady slide hides any scale, clock or turn of the axes in its initial state).
MEASUREMENT_SCENES = ("projectile", "puck_kicked")
#: The recording's errors of a measurement case: one of the camera's scale, the clock, the turn
#: of the axes, or all three at once.
DISTORTIONS = ("scale", "clock", "rotation", "all")
#: The real forces of the same size in each scene (a uniform pull is ``constant_force`` in a side
#: view and ``table_tilt`` from above, where those are offered), and what a reference fixes in
#: those cases: the length scale and the frame rate.
REAL_FORCES = {
    "projectile": ("constant_force", "linear_drag"),
    "puck_kicked": ("table_tilt", "linear_drag"),
}
REAL_REFERENCES = ("scale", "clock")


@dataclass(frozen=True)
class MeasurementCase:
    """One case of the measurement benchmark: ``kind`` ``"measurement"`` (a recording distorted by
    ``label``, one of :data:`DISTORTIONS`, with no force) or ``"physical"`` (a real force
    ``label`` of the same size, with scale and clock fixed by a reference), the synthetic run
    and the discovery settings it is judged with."""

    kind: str
    scene: str
    label: str
    seed: int
    case: SyntheticRun
    settings: Any


def distortion_values(label: str, rng: np.random.Generator) -> dict[str, dict[str, float]]:
    """The errors of distortion ``label``: a length scale and a clock each 1-3 % off, axes turned
    by 0.3-1°, or all three, each sign at random."""
    out: dict[str, dict[str, float]] = {}
    if label in ("scale", "all"):
        out["calibration_scale"] = {"scale": 1.0 + _sign(rng) * float(rng.uniform(0.01, 0.03))}
    if label in ("clock", "all"):
        out["clock_scale"] = {"scale": 1.0 + _sign(rng) * float(rng.uniform(0.01, 0.03))}
    if label in ("rotation", "all"):
        out["axis_rotation"] = {"angle": _sign(rng) * math.radians(float(rng.uniform(0.3, 1.0)))}
    if not out:
        raise KeyError(f"distortion {label!r}: expected one of {', '.join(DISTORTIONS)}")
    return out


def real_force_values(effect: str, scene: Scene, rng: np.random.Generator) -> dict[str, float]:
    """A real ``effect`` as large as the distortions: a uniform pull of 0.1-0.3 m/s² in a random
    direction (what a 1-3 % scale or a 0.6-1.8° turn of the axes gives in free flight), or linear
    drag slowing the body by about as much at its typical speed."""
    m = float(np.mean([b.mass for b in scene.bodies]))
    if effect in ("constant_force", "table_tilt"):
        mag, ang = float(rng.uniform(0.1, 0.3)), float(rng.uniform(0, 2 * math.pi))
        k = ("fx", "fy") if effect == "constant_force" else ("ax", "ay")
        f = m if effect == "constant_force" else 1.0
        return {k[0]: f * mag * math.cos(ang), k[1]: f * mag * math.sin(ang)}
    if effect == "linear_drag":
        speed = float(np.mean([math.hypot(*b.velocity) for b in scene.bodies]))
        return {"c": m * float(rng.uniform(0.1, 0.3)) / speed}
    raise KeyError(effect)


def measurement_case(
    kind: str, scene_kind: str, label: str, seed: int, engine: Any
) -> MeasurementCase:
    """One case of the measurement benchmark (see :class:`MeasurementCase`), seeded."""
    from physbench.discover.settings import Settings

    salt = 1000 + 10 * sorted(SCENES).index(scene_kind)
    if kind == "measurement":
        rng = _rng(seed, salt + DISTORTIONS.index(label))
        case = make_case(None, scene_kind, seed, engine, distortion=distortion_values(label, rng))
        settings = Settings()
    elif kind == "physical":
        rng = _rng(seed, salt + 5 + REAL_FORCES[scene_kind].index(label))
        scene = SCENES[scene_kind](_rng(seed, 1 + sorted(SCENES).index(scene_kind)))
        truth = real_force_values(label, scene, rng)
        case = make_case(label, scene_kind, seed, engine, truth=truth)
        settings = Settings(references=REAL_REFERENCES)
    else:
        raise KeyError(f"kind {kind!r}: expected 'measurement' or 'physical'")
    return MeasurementCase(kind, scene_kind, label, seed, case, settings)


def judge_measurement(mc: MeasurementCase, disc: Any) -> dict[str, Any]:
    """The benchmark's verdict on one discovery ``disc`` of ``mc``: for a measurement case,
    whether it lists a measurement cause (as a cause or as an explanation it cannot tell apart
    from one) and whether it names a physical cause alone; for a real force, whether that force
    is the first cause, whether it is named alone, and its magnitude error. ``ok``: the claim the
    benchmark holds (measurement: no physical cause alone, and a measurement cause listed unless
    nothing at all is named, as for a distortion within the noise; physical: named first).
    "Alone" for a physical cause: no measurement error explains the data as well."""
    causes = list(disc.causes)
    results = {c.effect: c for c in disc.cause_results}
    measured = [c for c in causes if is_measurement(results[c].name)]
    rivals = [disc.ambiguity(c) for c in causes]
    listed = bool(measured) or any(a is not None and not a.physical_alone for a in rivals)
    alone = [
        c
        for c, a in zip(causes, rivals, strict=True)
        if not is_measurement(results[c].name) and (a is None or a.physical_alone)
    ]
    out: dict[str, Any] = {
        "causes": causes,
        "named_alone": [c for c, a in zip(causes, rivals, strict=True) if a is None],
        "indistinguishable": {
            a.cause: [list(m) for m in a.members] for a in rivals if a is not None
        },
        "gain": disc.gain,
    }
    if mc.kind == "measurement":
        # a distortion the recording cannot see names nothing, which is no claim of a force
        out.update(
            lists_measurement=listed,
            physical_alone=alone,
            no_cause=not causes,
            ok=(listed or not causes) and not alone,
        )
        return out
    first = causes[:1] == [mc.label]
    amb = disc.ambiguity(mc.label) if first else None
    error = magnitude_error(mc.label, mc.case.truth, results[mc.label].params) if first else None
    out.update(
        named_first=first,
        alone=first and (amb is None or amb.physical_alone),
        measurement_rivals=[] if amb is None else [r.names for r in amb.rivals if r.measurement],
        magnitude_error=error,
        ok=first,
    )
    return out
