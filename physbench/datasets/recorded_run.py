"""One recorded run of a data set and the scene that reproduces its setup."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from physbench.recording import Recording
from physbench.scene import Scene


@dataclass(frozen=True, eq=False)
class DatasetRun:
    """One recorded run and the scene that reproduces its setup (geometry, masses and initial state
    from the data; the plain rigid-body model otherwise), so that simulating ``scene`` and calling
    ``recording.residuals(traj)`` measures what the plain model misses.

    ``expected_effects`` names the effects (registered names) that the provenance says the plain
    model misses, for checking what discovery finds; ``notes`` holds assumptions and reference
    values.
    """

    name: str
    scene: Scene
    recording: Recording
    expected_effects: tuple[str, ...] = ()
    notes: Mapping[str, object] = field(default_factory=dict)
