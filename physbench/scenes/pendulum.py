"""pendulum: a rigid arm on a pivot, matching the real free-swing recordings in ``shared/data``.

Two rigs (``rig=``), geometry, mass and units from their PROVENANCE.md:

* ``"kaheman"`` (default; Kaheman et al. 2022, ``pendulum_kaheman``, single arm): centre of mass
  a = 0.14775 m below the pivot, m = 0.14758 kg, moment of inertia about the centre of mass
  I = 1.0912e-4 kg·m² (the authors' fit), g = 9.81, encoder angles at 1 kHz.
* ``"benard"`` (``pendulum_benard``): a uniform rod ≈0.13 m long, ≈0.1 kg with its hinge, pivoted
  at one end (a = 0.065 m, I = m L²/12), angles at a nominal 1 kHz.

The arm is drawn as a thin box from the pivot to twice its centre-of-mass distance, along its
body frame's -y axis (as in :mod:`physbench.datasets`); its ``moment`` is set explicitly, so the
drawn shape does not set the dynamics. The body angle is the arm's deflection from hanging
straight down, counter-clockwise positive (the data's angle after subtracting the rest angle).

Base-model unknown: ``arm.moment``. With the pivot fixed, the rigid model's motion depends on mass
only through ``m a / (I + m a²)``; the mass is weighed, so the moment of inertia is what the rigid
model can identify (it sets the period with ``a``). The data's amplitude decay comes from pivot
friction and air drag, which are not part of the rigid model: they are added as effects
(``joint_viscous_damping``, ``joint_coulomb_friction``, ``joint_quadratic_damping``) in the
discrepancy-discovery part.

Both engines' pivot joints lose energy in proportion to the step; at the default 20 substeps per
1 kHz frame that is ≈0.0011-0.0015 rad of amplitude per cycle, 2-12 % of the real rigs' losses
(pass ``substeps=40`` to halve it). Box2D cannot build a box thinner than 2 cm (its 1 cm polygon
skin), hence the 3 cm arms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from physbench.scene import Body, Box, Joint, Scene, body_unknown
from physbench.scenes.generator import scene_generator


@dataclass(frozen=True)
class Rig:
    com_distance: float  # m, pivot to centre of mass
    mass: float  # kg
    moment: float  # kg·m² about the centre of mass
    moment_range: tuple[float, float]
    thickness: float  # m, drawn width of the arm
    amplitude: tuple[float, float]  # rad, range of the seeded initial deflection
    gravity: float = 9.81


RIGS: dict[str, Rig] = {
    "kaheman": Rig(0.14775, 0.14758, 1.0912e-4, (1e-5, 1e-3), 0.03, (1.2, 1.8)),
    "benard": Rig(0.065, 0.1, 0.1 * 0.13**2 / 12, (1e-5, 1e-3), 0.03, (1.0, 2.6)),
}
FPS = 1000.0


@scene_generator(
    "pendulum", "rigid arm on a pivot, the real single-pendulum rigs (1 kHz encoder angles)"
)
def generate(
    seed: int = 0,
    rig: str = "kaheman",
    angle: float | None = None,
    omega: float = 0.0,
    frames: int = 2000,
    fps: float = FPS,
    substeps: int = 20,
) -> Scene:
    """The ``rig`` pendulum released at deflection ``angle`` (rad from hanging down, CCW; None:
    drawn from the seed in the rig's range) with rate ``omega`` (rad/s)."""
    if rig not in RIGS:
        raise ValueError(f"rig = {rig!r}: expected one of {', '.join(RIGS)}")
    p = RIGS[rig]
    rng = np.random.default_rng([seed, 5])
    phi = rng.uniform(*p.amplitude) if angle is None else float(angle)
    a = p.com_distance
    half = 2 * a + 0.05  # half the world's side: the arm fits at any angle
    pivot = (half, half)
    arm = Body(
        "arm",
        Box(p.thickness, 2 * a),
        (pivot[0] + a * math.sin(phi), pivot[1] - a * math.cos(phi)),
        angle=phi,
        angular_velocity=omega,
        velocity=(a * omega * math.cos(phi), a * omega * math.sin(phi)),
        mass=p.mass,
        moment=p.moment,
    )
    return Scene(
        name="pendulum",
        bodies=(arm,),
        bounds=(0.0, 0.0, 2 * half, 2 * half),
        gravity=(0.0, -p.gravity),
        fps=fps,
        frames=frames,
        substeps=substeps,
        joints=(Joint("arm", pivot),),
        unknowns=(body_unknown("arm", "moment", *p.moment_range),),
        description=generate.description,
        meta={"seed": seed, "rig": rig},
    )
