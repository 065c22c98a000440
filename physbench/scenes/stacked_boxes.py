"""stacked_boxes (paper Fig. 2c): a test circle shot into a stack of two unknown square boxes.

Two 0.5 m boxes stand on the floor of a bin, ``upper`` on ``lower``. The test circle rolls in from
the left and strikes ``lower`` at its centre height, so ``lower`` slides out from under ``upper``.
Contacts multiply the two surfaces' friction (the floor's is 1), so ``lower`` slides on the floor
with its own friction and ``upper`` is dragged by ``lower.friction * upper.friction``: the drag can
never match the floor's grip, so ``upper`` always slips on ``lower``, lags behind and tips off the
back onto the floor or onto the test circle, which follows ``lower``. Friction is therefore seen
through sliding distances for every value in the range; boxes never stick or topple forward (that
would need friction > 1).
"""

from __future__ import annotations

import numpy as np

from physbench.scene import Body, Box, Circle, Force, Scene, body_unknown
from physbench.scenes.bin import bin_walls
from physbench.scenes.generator import scene_generator

BOUNDS = (0.0, 0.0, 4.0, 4.0)
INSET = 0.15  # the floor is at y = 0.15 so that a box resting on it lies inside the bounds
SIDE = 0.5
RADIUS = 0.25  # test circle; rolling on the floor it strikes ``lower`` at mid-height
TEST_MASS = 5.0
MASS_RANGE = (2.0, 8.0)
FRICTION_RANGE = (0.2, 1.0)
BOX_ELASTICITY = 0.5
PUSH_TIME = 0.1  # s the test circle is pushed for
SPEED = 10.0  # m/s of the test circle after the push (+-0.5 per seed)


@scene_generator("stacked_boxes", "test circle shot into a stack of two unknown square boxes")
def generate(seed: int = 0) -> Scene:
    """Two stacked boxes in a bin; ``lower`` and ``upper`` have unknown mass and friction."""
    rng = np.random.default_rng([seed, 3])
    s, r, y0 = SIDE, RADIUS, INSET
    xl = 1.6 + rng.uniform(-0.1, 0.1)
    xu = xl + rng.uniform(-0.05, 0.05)
    xt = 0.5 + rng.uniform(-0.1, 0.1)
    f = TEST_MASS * (SPEED + rng.uniform(-0.5, 0.5)) / PUSH_TIME
    push = Force("test", (f, 0.0), 0.0, PUSH_TIME)
    m0, f0 = sum(MASS_RANGE) / 2, sum(FRICTION_RANGE) / 2
    e = BOX_ELASTICITY
    bodies = (
        Body("test", Circle(r), (xt, y0 + r), mass=TEST_MASS, elasticity=0.8, friction=0.3),
        Body("lower", Box(s, s), (xl, y0 + s / 2), mass=m0, elasticity=e, friction=f0),
        Body("upper", Box(s, s), (xu, y0 + 1.5 * s), mass=m0, elasticity=e, friction=f0),
    )
    unknowns = tuple(
        body_unknown(name, p, lo, hi)
        for name in ("lower", "upper")
        for p, (lo, hi) in (("mass", MASS_RANGE), ("friction", FRICTION_RANGE))
    )
    return Scene(
        name="stacked_boxes",
        bodies=bodies,
        bounds=BOUNDS,
        statics=bin_walls(BOUNDS, inset=INSET),
        forces=(push,),
        unknowns=unknowns,
        test_body="test",
        description=generate.description,
        meta={"seed": seed},
    )
