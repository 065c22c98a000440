"""The bin: a floor and two walls as static segments, shared by the paper's bin scenes."""

from __future__ import annotations

from physbench.scene import Segment


def bin_walls(bounds: tuple[float, float, float, float], *, ceiling: bool = False,
              elasticity: float = 1.0, friction: float = 1.0) -> tuple[Segment, ...]:
    """Segments along the floor and sides of ``bounds`` (and the top if ``ceiling``)."""
    x0, y0, x1, y1 = bounds
    corners = [((x0, y0), (x1, y0)), ((x0, y0), (x0, y1)), ((x1, y0), (x1, y1))]
    if ceiling:
        corners.append(((x0, y1), (x1, y1)))
    return tuple(Segment(a, b, 0.0, elasticity, friction) for a, b in corners)
