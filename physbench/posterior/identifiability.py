"""Whether each unknown can be seen at all: a cheap probe before a run.

An unknown that changes no pixel of the rendered frames (a falling ball's mass without drag) cannot
be identified from them; any estimate of it is the initial guess or noise. The probe moves each
unknown by ±10 % of its range around a point (the run's initial guess), simulates and renders, and
measures how far the frames move: two simulations and renders per unknown.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import SimulationError
from physbench.metrics import image_mse
from physbench.unknowns import simulate_seen

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.render.base import Renderer
    from physbench.scene import Scene
    from physbench.simulators.base import Simulator
    from physbench.unknowns import ParamSpace

#: The probe's step, as a fraction of each unknown's range.
STEP = 0.1
#: Frames whose summed squared change (over every pixel and channel) is below this are the same
#: to an estimator: a hundredth of one pixel going from black to white is 1e-4.
INVISIBLE = 1e-4


@dataclass(frozen=True)
class Probe:
    """How far the rendered frames move when one unknown moves around ``at``."""

    key: str
    at: float
    low: float
    high: float
    #: The larger image MSE between the frames at ``at`` and at ``low`` / ``high``.
    change: float
    #: Pixel values in the frames (to turn the mean change into a total).
    size: int

    @property
    def visible(self) -> bool:
        return self.change * self.size >= INVISIBLE


def probe(
    scene: Scene,
    space: ParamSpace,
    simulator: Simulator,
    renderer: Renderer,
    at: Mapping[str, float],
    *,
    effects: Sequence[Effect] = (),
    step: float = STEP,
) -> list[Probe]:
    """Called by :func:`~physbench.experiment.run_config` before the loop starts: one
    :class:`Probe` per unknown of ``space`` around the parameters ``at``. A probe whose simulation
    fails counts as visible (the unknown changes something)."""
    base = dict(at)

    def frames(params: Mapping[str, float]) -> np.ndarray | None:
        try:
            seen, traj = simulate_seen(simulator, scene, params, effects)
        except SimulationError:
            return None
        return renderer.render(seen, traj)

    ref = frames(base)
    if ref is None:
        return []
    out = []
    for u in space.unknowns:
        delta = step * (u.high - u.low)
        low, high = max(u.low, base[u.key] - delta), min(u.high, base[u.key] + delta)
        change = 0.0
        for value in (low, high):
            moved = frames({**base, u.key: value})
            change = max(change, np.inf if moved is None else image_mse(moved, ref))
        out.append(Probe(u.key, base[u.key], low, high, float(change), int(ref.size)))
    return out


def unseen(probes: Sequence[Probe]) -> tuple[str, ...]:
    """The unknowns whose probe moved no pixel."""
    return tuple(p.key for p in probes if not p.visible)


def describe(probes: Sequence[Probe]) -> str | None:
    """One sentence about the unseen unknowns, or ``None`` when every unknown is seen."""
    hidden = [p for p in probes if not p.visible]
    if not hidden:
        return None
    names = ", ".join(f"{p.key} (tried {p.low:.4g} to {p.high:.4g})" for p in hidden)
    verb = "changes" if len(hidden) == 1 else "change"
    return (
        f"{names} {verb} no pixel of the rendered frames around the initial guess: the "
        "observation cannot identify "
        + ("it" if len(hidden) == 1 else "them")
        + "; the estimate is a guess. Fix "
        + ("it" if len(hidden) == 1 else "them")
        + " to a measured value, or observe what "
        + ("it" if len(hidden) == 1 else "they")
        + " affects"
    )
