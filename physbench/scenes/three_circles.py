"""three_circles (paper Fig. 2a): a test circle accelerated from above onto two unknown circles."""

from __future__ import annotations

import numpy as np

from physbench.scene import Body, Circle, Force, Scene, Unknown
from physbench.scenes import scene_generator
from physbench.scenes.bin import bin_walls

BOUNDS = (0.0, 0.0, 4.0, 4.0)


@scene_generator("three_circles", "test circle shot down-right onto two unknown circles on the floor")
def generate(seed: int = 0) -> Scene:
    rng = np.random.default_rng([seed, 1])
    r = 0.3
    xa = 1.6 + rng.uniform(-0.15, 0.15)
    xb = xa + 2 * r + rng.uniform(0.02, 0.1)
    test = Body("test", Circle(r), (0.7 + rng.uniform(-0.1, 0.1), 2.6 + rng.uniform(-0.2, 0.2)), mass=5.0, elasticity=0.5, friction=0.3)
    a = Body("a", Circle(r), (xa, r), mass=5.0, elasticity=0.5, friction=0.3)
    b = Body("b", Circle(r), (xb, r), mass=5.0, elasticity=0.5, friction=0.3)
    push = Force("test", (250.0 + rng.uniform(-20, 20), -150.0), 0.0, 0.2)
    unknowns = tuple(
        Unknown(n, p, lo, hi) for n in ("a", "b") for p, lo, hi in (("mass", 1.0, 10.0), ("elasticity", 0.1, 1.0))
    )
    return Scene(
        name="three_circles",
        bodies=(test, a, b),
        bounds=BOUNDS,
        statics=bin_walls(BOUNDS),
        forces=(push,),
        unknowns=unknowns,
        test_body="test",
        description=generate.__doc__ or "",
    )
