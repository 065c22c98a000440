"""bouncing_balls (paper Fig. 2d): a top-down pool table, a test ball shot into a rack of 2-6 balls.

There is no gravity (the table is seen from above) and four cushions bound it. The unknown balls
``b0..b5`` lie in a triangle with 1-3 cm gaps, filled row by row (apex, then the second row, then
the middle and the ends of the third), so every ball touches a ball of the row in front of it and
is struck through it. The test ball, of fixed mass, is pushed into the apex slightly off centre.

All balls have elasticity 0.5 (a ball-ball restitution of 0.25): a striking ball keeps about a
third of its speed and moves on, where with near-elastic balls of similar mass it would stop dead
as in a Newton's cradle and move only across its gap (measured: 0.15 m for the apex, 0 m for the
middle ball of the back row, which the two balls in front hit only along lines through the balls
beside it).
"""

from __future__ import annotations

import math

import numpy as np

from physbench.scene import Body, Circle, Force, Scene, Segment, body_unknown
from physbench.scenes.generator import scene_generator

BOUNDS = (0.0, 0.0, 4.0, 4.0)
RADIUS = 0.2
TEST_MASS = 5.0
MASS_RANGE = (2.0, 8.0)
ELASTICITY = 0.5
FRICTION = 0.2
PUSH_TIME = 0.1  # s the test ball is pushed for
SPEED = 8.0  # m/s of the test ball after the push (+-0.5 per seed)
MAX_BALLS = 6
#: Rack slots as (row, offset across the row in ball spacings), in fill order.
SLOTS = ((0, 0.0), (1, 0.5), (1, -0.5), (2, 0.0), (2, 1.0), (2, -1.0))


@scene_generator(
    "bouncing_balls", "top-down pool table: a test ball shot into a rack of 2-6 unknown balls"
)
def generate(seed: int = 0, n_balls: int | None = None) -> Scene:
    """A pool table with ``n_balls`` unknown-mass balls ``b0..`` (None: 2-6, drawn from the
    seed)."""
    rng = np.random.default_rng([seed, 4])
    n = int(rng.integers(2, MAX_BALLS + 1)) if n_balls is None else n_balls
    if isinstance(n, bool) or not 1 <= n <= MAX_BALLS:
        raise ValueError(f"n_balls = {n_balls!r}: expected a whole number 1..{MAX_BALLS} or None")
    r = RADIUS
    d = 2 * r + rng.uniform(0.01, 0.03)  # centre spacing in the rack
    ax, ay = 2.2 + rng.uniform(-0.1, 0.1), 2.0 + rng.uniform(-0.1, 0.1)  # apex
    m0 = sum(MASS_RANGE) / 2
    balls = tuple(
        Body(
            f"b{i}",
            Circle(r),
            (ax + row * d * math.sqrt(3) / 2, ay + across * d),
            mass=m0,
            elasticity=ELASTICITY,
            friction=FRICTION,
        )
        for i, (row, across) in enumerate(SLOTS[:n])
    )
    start = (0.6 + rng.uniform(-0.1, 0.1), ay + rng.uniform(-0.05, 0.05))
    dx, dy = ax - start[0], ay + rng.uniform(-0.05, 0.05) - start[1]
    norm = math.hypot(dx, dy)
    f = TEST_MASS * (SPEED + rng.uniform(-0.5, 0.5)) / PUSH_TIME
    push = Force("test", (f * dx / norm, f * dy / norm), 0.0, PUSH_TIME)
    test = Body("test", Circle(r), start, mass=TEST_MASS, elasticity=ELASTICITY, friction=FRICTION)
    x0, y0, x1, y1 = BOUNDS
    corners = ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
    cushions = tuple(Segment(corners[i], corners[(i + 1) % 4], 0.0, 1.0, 1.0) for i in range(4))
    return Scene(
        name="bouncing_balls",
        bodies=(test, *balls),
        bounds=BOUNDS,
        gravity=(0.0, 0.0),
        statics=cushions,
        forces=(push,),
        unknowns=tuple(body_unknown(b.name, "mass", *MASS_RANGE) for b in balls),
        test_body="test",
        description=generate.description,
        meta={"seed": seed, "n_balls": n},
    )
