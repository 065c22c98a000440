"""ball_drop: a ball dropped from ≈47 m, matching de Silva et al.'s ball drops
(``ball_drops_desilva``).

Geometry and units follow the data's PROVENANCE.md: heights in m, 15 frames per second, drops from
45.5-49.5 m recorded for 2.8-3.9 s. Each ball's mass and radius come from the authors'
``balls.txt`` (mass = 0.0283495 kg/oz, radius = circumference / 2π); the volleyball, whose weight
and size are unknown, is left out. A 2 m thick ground slab at y = 0 stops the ball (a thin segment
would let a 2 cm ball at 30 m/s pass between two pymunk steps); the data end at 11-13 m, before
the ground.

Base-model unknown: ``ball.mass``, in [0.5, 2] times the weighed mass. The rigid free-fall model
cannot identify it (every mass falls alike): the data's departure from free fall is air drag,
which the discrepancy-discovery part adds as an effect (``quadratic_drag``, force ``-c|v|v``).
With drag only ``c / m`` is identifiable, so fix one of the two; the weighed mass is the nominal
value.
"""

from __future__ import annotations

import math

import numpy as np

from physbench.scene import Body, Circle, Scene, StaticPolygon, body_unknown
from physbench.scenes.generator import scene_generator

OZ = 0.0283495  # kg per ounce
#: name (as the data's CSV files) -> (weight in oz, circumference in cm), from ``balls.txt``.
BALLS: dict[str, tuple[float, float]] = {
    "baseball": (5.0, 22.25),
    "blue_basketball": (18.0, 75.0),
    "green_basketball": (16.0, 73.25),
    "bowling_ball": (81.0, 67.0),
    "golf_ball": (1.62, 13.8),
    "tennis_ball": (2.0, 20.75),
    "whiffle_ball_1": (1.0, 22.8),
    "whiffle_ball_2": (1.0, 22.8),
    "yellow_whiffle_ball": (1.5, 29.0),
    "orange_whiffle_ball": (1.5, 29.0),
}
FPS = 15.0
HALF_WIDTH = 1.0
TOP = 52.0


def ball_properties(ball: str) -> tuple[float, float]:
    """``(mass kg, radius m)`` of a ball of the data set."""
    if ball not in BALLS:
        raise ValueError(f"ball = {ball!r}: expected one of {', '.join(BALLS)}")
    oz, cm = BALLS[ball]
    return oz * OZ, cm / (200 * math.pi)


@scene_generator("ball_drop", "a ball dropped from about 47 m, the real ball-drop data (15 fps)")
def generate(
    seed: int = 0,
    ball: str = "golf_ball",
    height: float | None = None,
    velocity: float = 0.0,
    frames: int = 60,
    fps: float = FPS,
    substeps: int = 10,
) -> Scene:
    """``ball`` released at ``height`` m (None: 45.5-49.5 m from the seed) moving at ``velocity``
    m/s (up positive)."""
    mass, radius = ball_properties(ball)
    rng = np.random.default_rng([seed, 6])
    y0 = rng.uniform(45.5, 49.5) if height is None else float(height)
    w = HALF_WIDTH
    ground = StaticPolygon(
        ((-w, -2.0), (w, -2.0), (w, 0.0), (-w, 0.0)), elasticity=1.0, friction=1.0
    )
    body = Body(
        "ball",
        Circle(radius),
        (0.0, y0),
        velocity=(0.0, velocity),
        mass=mass,
        elasticity=0.5,
        friction=0.5,
    )
    return Scene(
        name="ball_drop",
        bodies=(body,),
        bounds=(-w, 0.0, w, TOP),
        fps=fps,
        frames=frames,
        substeps=substeps,
        statics=(ground,),
        unknowns=(body_unknown("ball", "mass", 0.5 * mass, 2.0 * mass),),
        description=generate.description,
        meta={"seed": seed, "ball": ball},
    )
