"""second_order (paper Fig. 2b): a test circle shot sideways into ``a``, which then strikes ``b``.

All three circles rest on the floor of a bin. The test circle is pushed to the right into ``a``;
``a`` rolls across a 0.35-0.5 m gap into ``b`` (so ``a`` moves at least the gap), and ``b`` runs
towards the right wall (in about 60 % of the seeds it reaches the wall, and comes back into ``a``,
within the second). ``b`` is only set moving through ``a``: a second-order collision.
"""

from __future__ import annotations

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
SPEED = 7.0  # m/s of the test circle after the push (+-0.5 per seed)
XA = 1.6  # m, x of circle a (+-0.1 per seed)
GAP = (0.35, 0.5)  # m between a and b


@scene_generator(
    "second_order", "test circle shot sideways into one unknown circle, which strikes the other"
)
def generate(seed: int = 0) -> Scene:
    """Three circles on the floor of a bin; ``a`` and ``b`` have unknown mass and elasticity."""
    rng = np.random.default_rng([seed, 2])
    r = RADIUS
    xa = XA + rng.uniform(-0.1, 0.1)
    xb = xa + 2 * r + rng.uniform(*GAP)
    xt = 0.5 + rng.uniform(-0.1, 0.1)
    f = TEST_MASS * (SPEED + rng.uniform(-0.5, 0.5)) / PUSH_TIME
    push = Force("test", (f, 0.0), 0.0, PUSH_TIME)
    m0, e0 = sum(MASS_RANGE) / 2, sum(ELASTICITY_RANGE) / 2
    bodies = (
        Body("test", Circle(r), (xt, r), mass=TEST_MASS, elasticity=0.8, friction=FRICTION),
        Body("a", Circle(r), (xa, r), mass=m0, elasticity=e0, friction=FRICTION),
        Body("b", Circle(r), (xb, r), mass=m0, elasticity=e0, friction=FRICTION),
    )
    unknowns = tuple(
        body_unknown(name, p, lo, hi)
        for name in ("a", "b")
        for p, (lo, hi) in (("mass", MASS_RANGE), ("elasticity", ELASTICITY_RANGE))
    )
    return Scene(
        name="second_order",
        bodies=bodies,
        bounds=BOUNDS,
        statics=bin_walls(BOUNDS),
        forces=(push,),
        unknowns=unknowns,
        test_body="test",
        description=generate.description,
        meta={"seed": seed},
    )
