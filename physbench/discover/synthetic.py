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
    if effect == "clock_scale":  # the magnitude is the deviation from a true clock
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
) -> SyntheticRun:
    """One synthetic run of ``scene_kind`` (see :data:`SCENES`) with ``effect`` hidden at a random
    magnitude (None: a control), simulated by ``engine`` (a simulator instance). ``truth``: the
    hidden values instead (missing ones random), beyond the effect's declared ranges if need be
    (an extensible range is widened to hold them; the random draws are made all the same, so the
    scene and the noise do not change). ``body_params``: body parameters (``{"ball.mass": 80}``)
    applied to the drawn scene, for magnitudes that need a heavier or larger body to stay
    visible without swamping the motion."""
    from physbench.components import create
    from physbench.effects import apply_measurements

    rng = _rng(seed, 1 + sorted(SCENES).index(scene_kind))
    scene = SCENES[scene_kind](rng).with_params(body_params or {}).validate()
    values: dict[str, float] = {}
    effects = []
    if effect is not None:
        values = {**hidden_values(effect, scene, rng), **(truth or {})}
        eff = create("effect", effect)
        for p in eff.parameters():
            wide = p
            while not wide.contains(values.get(p.name, 0.0)) and wide.extensible:
                wide = wide.widened()
            if wide is not p:
                eff.widen(p.name, wide.low, wide.high)
        eff.setup(scene, values)
        effects = [eff]
    t_end = (scene.frames - 1) / scene.fps
    scale = values.get("scale", 1.0)
    sim_scene = (
        scene if scale <= 1 else replace(scene, frames=math.ceil(t_end * scale * scene.fps) + 2)
    )
    traj = apply_measurements(engine.simulate(sim_scene, effects=effects), effects)
    rec = _record(scene_kind, scene, traj, t_end, rng)
    name = f"{effect or 'control'}/{scene_kind}/{seed}"
    return SyntheticRun(
        name,
        scene_kind,
        Run(name, _blur(scene, rng), recording=rec, source="synthetic"),
        effect,
        values,
        trajectory=traj,
    )


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
