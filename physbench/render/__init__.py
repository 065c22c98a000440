"""Renderers: trajectory -> ``(T, C, H, W)`` float32 frames in [0, 1].

:mod:`physbench.render.base` holds the contract (:class:`Renderer`), the channel layouts and the
observation model (:class:`ObservationModel`: blur and noise of observed frames);
:class:`~physbench.render.raster.RasterRenderer` is the built-in renderer (registered as
``raster``); :mod:`physbench.render.observe` holds the image filters and
:func:`physbench.render.preview.save_preview` writes a GIF or PNG for people to look at.
"""

from __future__ import annotations

from physbench.render.base import (
    DEFAULT_RENDERER,
    MODES,
    ObservationModel,
    Renderer,
    RenderError,
)
from physbench.render.raster import RasterRenderer

__all__ = [
    "DEFAULT_RENDERER",
    "MODES",
    "ObservationModel",
    "RasterRenderer",
    "RenderError",
    "Renderer",
]
