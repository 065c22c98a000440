"""The Simulator contract: a physics engine that builds any :class:`~physbench.scene.Scene`.

The built-in engines (:mod:`~physbench.simulators.pymunk_sim`,
:mod:`~physbench.simulators.box2d_sim`) derive from
:class:`~physbench.simulators.stepping.SteppingSimulator`, which implements :meth:`simulate` once
for any engine that can step a world; a third-party engine may do the same or implement
:meth:`Simulator.simulate` itself. ``physbench.testing.check_simulator`` runs the conformance kit.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, ClassVar

from physbench.requirements import Requirements

if TYPE_CHECKING:
    from physbench.effects.base import Effect
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

#: The engine a run uses unless told otherwise.
DEFAULT_SIMULATOR = "pymunk"


class Simulator(Requirements):
    """Base class of every simulator (plugin contract). The framework builds it with keyword
    options (``Cls(**options)``) and calls :meth:`simulate` once per iteration."""

    #: Registered name (unique among simulators).
    name: ClassVar[str] = ""

    def simulate(
        self,
        scene: Scene,
        params: Mapping[str, float] | None = None,
        *,
        effects: Sequence[Effect] = (),
    ) -> Trajectory:
        """Called once per iteration: build ``scene`` with ``params`` (``{"body.param": value}``,
        plus ``"<effect key>.<param>"`` values for ``effects``) applied, step it for
        ``scene.frames`` frames and return the trajectory. Before building, call each effect's
        ``setup`` with the scene as simulated; apply their forces every substep and their contact
        law when a contact starts. Raises :class:`~physbench.errors.SimulationError` when the
        simulation explodes (NaN, a body far outside the world, an engine speed limit)."""
        raise NotImplementedError(f"{type(self).__name__} must implement simulate()")
