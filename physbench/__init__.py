"""physbench: identify physical object properties from video or trajectories, and benchmark the
methods that do it (Link, Schwarz, Behnke, IJCNN 2022)."""

from __future__ import annotations

__version__ = "0.2.0"
