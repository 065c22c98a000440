"""The bin: a floor and two walls as static segments, shared by the paper's bin scenes."""

from __future__ import annotations

from physbench.scene import Segment


def bin_walls(
    bounds: tuple[float, float, float, float],
    *,
    inset: float = 0.0,
    ceiling: bool = False,
    elasticity: float = 1.0,
    friction: float = 1.0,
) -> tuple[Segment, ...]:
    """Segments along the floor and sides of ``bounds`` moved ``inset`` m inwards (and the top if
    ``ceiling``).

    Walls are perfectly elastic with friction 1 by default: contacts multiply the two surfaces'
    values, so a body meets a wall with its own elasticity and friction.
    An inset keeps bodies resting on the floor inside the world bounds, which scene validation
    checks with the body's circumscribed circle (a box on the floor needs ``inset`` >= (√2-1)/2 of
    its side).
    """
    x0, y0, x1, y1 = bounds[0] + inset, bounds[1] + inset, bounds[2] - inset, bounds[3] - inset
    sides = [((x0, y0), (x1, y0)), ((x0, y0), (x0, y1)), ((x1, y0), (x1, y1))]
    if ceiling:
        sides.append(((x0, y1), (x1, y1)))
    return tuple(Segment(a, b, 0.0, elasticity, friction) for a, b in sides)
