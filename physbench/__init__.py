"""physbench: identify physical object properties from video or trajectories, and benchmark the
methods that do it (Link, Schwarz, Behnke, IJCNN 2022).

The Python API (:mod:`physbench.api`) is reachable from here: ``physbench.make_scene``,
``simulate``, ``render_frames``, ``refine``, ``run``, ``sweep`` (``example`` names a shipped
spec), ``load_table``, ``read_recording`` and ``discover_effects``. They load on first use, so
that ``import physbench`` (which every ``physbench`` command does) stays free of numpy and the
engines.
"""

from __future__ import annotations

__version__ = "0.2.0"

#: The public entry points, defined in :mod:`physbench.api`.
__all__ = [
    "discover_effects",
    "example",
    "load_table",
    "make_scene",
    "read_recording",
    "refine",
    "render_frames",
    "run",
    "simulate",
    "sweep",
]


def __getattr__(name: str) -> object:
    """Called for a name this module lacks: the API functions, imported on first use."""
    if name in __all__:
        from physbench import api

        value = getattr(api, name)
        globals()[name] = value  # later look-ups skip this hook
        return value
    raise AttributeError(f"module 'physbench' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
