"""three_circles (paper Fig. 2a): a test circle shot down from above onto two unknown circles.

Circles ``a`` and ``b`` rest on the floor of a bin, 0.35-0.5 m apart. The test circle starts up
and to the left and is pushed diagonally down onto the upper left of ``a``, which is driven into
the floor and to the right; ``a`` rolls across the gap into ``b``, which runs towards the right
wall (reaching it within the second in about 60 % of the seeds). So ``a`` moves at least the gap,
and each unknown's elasticity also acts on a contact with a static (the floor for ``a``, the wall
for ``b``), where the restitution is that body's own and not only a product with another
unknown's.
"""

from __future__ import annotations

import math

import numpy as np

from physbench.scene import Body, Circle, Force, Scene, body_unknown
from physbench.scenes.bin import bin_walls
from physbench.scenes.generator import scene_generator

BOUNDS = (0.0, 0.0, 4.0, 4.0)
RADIUS = 0.3
TEST_MASS = 5.0
MASS_RANGE = (2.0, 8.0)
ELASTICITY_RANGE = (0.4, 1.0)
FRICTION = 0.3
PUSH_TIME = 0.1  # s the test circle is pushed for
SPEED = 8.0  # m/s of the test circle after the push (+-0.5 per seed)
XA = 1.8  # m, x of circle a (+-0.1 per seed)
START_Y = 1.8  # m, height of the test circle (+-0.2 per seed)


@scene_generator(
    "three_circles", "test circle shot down from above onto two unknown circles in a bin"
)
def generate(seed: int = 0) -> Scene:
    """Three circles in a bin; ``a`` and ``b`` have unknown mass and elasticity."""
    rng = np.random.default_rng([seed, 1])
    r = RADIUS
    xa = XA + rng.uniform(-0.1, 0.1)
    xb = xa + 2 * r + rng.uniform(0.35, 0.5)
    start = (XA - 1.3 + rng.uniform(-0.1, 0.1), START_Y + rng.uniform(-0.2, 0.2))
    aim = (xa - 0.7 * r, 1.7 * r)  # upper left of a
    dx, dy = aim[0] - start[0], aim[1] - start[1]
    norm = math.hypot(dx, dy)
    f = TEST_MASS * (SPEED + rng.uniform(-0.5, 0.5)) / PUSH_TIME
    push = Force("test", (f * dx / norm, f * dy / norm), 0.0, PUSH_TIME)
    m0, e0 = sum(MASS_RANGE) / 2, sum(ELASTICITY_RANGE) / 2
    bodies = (
        Body("test", Circle(r), start, mass=TEST_MASS, elasticity=0.8, friction=FRICTION),
        Body("a", Circle(r), (xa, r), mass=m0, elasticity=e0, friction=FRICTION),
        Body("b", Circle(r), (xb, r), mass=m0, elasticity=e0, friction=FRICTION),
    )
    unknowns = tuple(
        body_unknown(name, p, lo, hi)
        for name in ("a", "b")
        for p, (lo, hi) in (("mass", MASS_RANGE), ("elasticity", ELASTICITY_RANGE))
    )
    return Scene(
        name="three_circles",
        bodies=bodies,
        bounds=BOUNDS,
        statics=bin_walls(BOUNDS),
        forces=(push,),
        unknowns=unknowns,
        test_body="test",
        description=generate.description,
        meta={"seed": seed},
    )
