"""Renderers: trajectory -> ``(T, C, H, W)`` float32 frames in [0, 1].

:mod:`physbench.render.base` holds the contract (:class:`Renderer`) and the channel layouts;
:class:`~physbench.render.raster.RasterRenderer` is the default built-in renderer (registered as
``raster``), :class:`~physbench.render.camera.CameraRenderer` films scenes like a real camera
(``camera``: ``rgb`` frames with perspective, lens, motion blur, light, noise and encoding);
:mod:`physbench.render.sensor` holds the observation model (:class:`SensorModel`: blur and
noise of observed frames) and its image filters, and
:func:`physbench.render.preview.save_preview` writes a GIF or PNG for people to look at.
"""

from __future__ import annotations

from physbench.render.base import DEFAULT_RENDERER, MODES, Renderer, RenderError
from physbench.render.camera import CameraRenderer
from physbench.render.raster import RasterRenderer
from physbench.render.sensor import SensorModel

__all__ = [
    "DEFAULT_RENDERER",
    "MODES",
    "CameraRenderer",
    "RasterRenderer",
    "RenderError",
    "Renderer",
    "SensorModel",
]
