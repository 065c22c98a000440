"""What a job will cost: its memory and an order of magnitude of its time, estimated from its
sizes before any work starts, and the refusal of a job that cannot finish on this machine.

Every command that simulates (``run``, ``simulate``, ``discover``, ``bench``, ``train``) calls
:func:`check` first, so that ``--iterations 1000000000`` or a scene of 1e5 frames x 1e4 substeps
is one sentence instead of a hang or a ``MemoryError``. Setting the environment variable
:data:`OVERRIDE` (``PHYSBENCH_NO_SIZE_CHECK=1``) runs such a job anyway. Stdlib only: the CLI
imports this before anything heavy.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from physbench.errors import PhysbenchError, counted

if TYPE_CHECKING:
    from physbench.scene import Scene

#: The environment variable that turns the refusal off (set it to 1).
OVERRIDE = "PHYSBENCH_NO_SIZE_CHECK"
#: Seconds per body per physics step. Measured on the 2-core development machine with pymunk:
#: ``Simulator.simulate`` of a 50-circle pile (300 frames x 10 substeps, settling under gravity
#: between walls) took 0.045 s = 3.0e-7 s per body-step, and three_circles at 300 x 100 took
#: 4.8e-7 s; rounded up to 1e-6 so that other engines and busier contacts stay within it.
STEP_SECONDS = 1e-6
#: Seconds per rendered pixel value: the raster renderer drew 300 frames x 2 channels x 256 x 256
#: (3.9e7 values) in 0.37 s on the same machine, about 1e-8 s each.
PIXEL_SECONDS = 1e-8
#: The longest job (estimated seconds of compute) that runs without the override: a day.
MAX_SECONDS = 24 * 3600.0
#: Bytes of a float32 pixel value and of a float64 state component.
_PIXEL_BYTES, _STATE_BYTES = 4, 8
#: Numbers a body's state holds per frame: x, y, angle, vx, vy, angular velocity.
_STATE_SIZE = 6


class SizeError(PhysbenchError, ValueError):
    """A job whose estimated memory or time exceeds what this machine allows."""


@dataclass(frozen=True)
class Cost:
    """What a job needs: ``memory`` bytes held at once and ``seconds`` of compute, an order of
    magnitude (``STEP_SECONDS`` per body-step plus ``PIXEL_SECONDS`` per rendered value)."""

    memory: float
    seconds: float

    def times(self, n: float) -> Cost:
        """``n`` of these one after another: the time adds up, the memory is reused."""
        return Cost(self.memory, self.seconds * n)

    def __add__(self, other: Cost) -> Cost:
        """Two jobs one after another."""
        return Cost(max(self.memory, other.memory), self.seconds + other.seconds)


def channels(mode: str | None, bodies: int) -> int:
    """Channels of a frame in render ``mode`` (``None``: the renderer's default, at most 3)."""
    return {"mark": 2, "instance": bodies, "mask": 1, "rgb": 3}.get(mode or "", 3)


def frames_bytes(frames: int, n_channels: int, resolution: int) -> float:
    """Bytes of a ``(frames, channels, resolution, resolution)`` float32 sequence."""
    return float(frames) * n_channels * resolution * resolution * _PIXEL_BYTES


def simulation(
    frames: int,
    substeps: int,
    bodies: int,
    *,
    resolution: int = 0,
    n_channels: int = 0,
    held: int = 1,
) -> Cost:
    """One simulation of ``frames`` x ``substeps`` steps of ``bodies``, rendered at
    ``resolution`` (0: not rendered), with ``held`` rendered sequences in memory at once."""
    pixels = float(frames) * n_channels * resolution * resolution
    states = float(frames) * bodies * _STATE_SIZE * _STATE_BYTES
    return Cost(
        memory=states + held * frames_bytes(frames, n_channels, resolution),
        seconds=float(frames) * substeps * bodies * STEP_SECONDS + pixels * PIXEL_SECONDS,
    )


def of_scene(scene: Scene, *, resolution: int = 0, mode: str | None = None, held: int = 1) -> Cost:
    """One simulation of ``scene`` (its frames, substeps and bodies), rendered in ``mode`` at
    ``resolution`` (0: not rendered) with ``held`` rendered sequences in memory at once."""
    n = len(scene.bodies)
    return simulation(
        scene.frames,
        scene.substeps,
        n,
        resolution=resolution,
        n_channels=channels(mode, n) if resolution else 0,
        held=held,
    )


def simulations(n: float, scene: Scene, resolution: int = 0) -> str:
    """``"12 simulations of 30 frames x 10 substeps x 3 bodies at 64 px"``, for messages."""
    at = f" at {resolution} px" if resolution else ""
    return (
        f"{counted(int(n), 'simulation')} of {counted(scene.frames, 'frame')} x "
        f"{counted(scene.substeps, 'substep')} x {counted(len(scene.bodies), 'body')}{at}"
    )


def available_memory() -> float:
    """Bytes this process can still allocate: ``MemAvailable`` of /proc/meminfo where there is
    one, else the free physical pages; ``inf`` when neither can be read."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (OSError, ValueError, AttributeError):
        return math.inf


def overridden() -> bool:
    """Whether :data:`OVERRIDE` is set to a true value (1, true, yes)."""
    return os.environ.get(OVERRIDE, "").strip().lower() in ("1", "true", "yes")


def _bytes(n: float) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n / 1e3:.3g} kB"


def _duration(s: float) -> str:
    steps = (("years", 365 * 86400.0, 1.0), ("days", 86400.0, 2.0), ("h", 3600.0, 1.0))
    for unit, size, least in (*steps, ("min", 60.0, 1.0)):
        if s >= least * size:
            return f"{s / size:.3g} {unit}"
    return f"{s:.3g} s"


def check(
    cost: Cost,
    what: str,
    fix: str,
    *,
    memory: Callable[[], float] = available_memory,
    max_seconds: float = MAX_SECONDS,
) -> None:
    """Called before a job starts: raise :class:`SizeError` when ``cost`` needs more memory than
    is available or more time than ``max_seconds``, unless :data:`OVERRIDE` is set. ``what``
    names the job and its sizes (``"30 frames x 10 substeps x 3 bodies, 12 simulations"``),
    ``fix`` the inputs that would make it smaller (``"--iterations"``)."""
    if overridden():
        return
    have = memory()
    over = []
    if cost.memory > have:
        over.append(f"{_bytes(cost.memory)} of memory, more than the {_bytes(have)} available")
    if cost.seconds > max_seconds:
        over.append(
            f"about {_duration(cost.seconds)} of compute, more than the "
            f"{_duration(max_seconds)} limit"
        )
    if over:
        raise SizeError(
            f"{what} would need {' and '.join(over)}; make {fix} smaller, or set {OVERRIDE}=1 to "
            "run it anyway"
        )
