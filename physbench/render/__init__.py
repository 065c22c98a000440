"""Renderers: trajectory -> ``(T, C, H, W)`` float32 frames in [0, 1].

:class:`~physbench.render.raster.RasterRenderer` is the built-in one (registered as ``raster``);
:mod:`physbench.render.observe` holds the optional observation models and
:func:`physbench.render.preview.save_preview` writes a GIF or PNG for people to look at.
"""

from __future__ import annotations

from physbench.render.raster import RasterRenderer, RenderError

__all__ = ["RasterRenderer", "RenderError"]
