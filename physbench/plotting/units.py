"""Axis labels with units, shared by every figure so the same quantity reads the same everywhere.

Frames hold pixel values in [0, 1], so an image MSE is in squared pixel-value units; a normalized
MSE is an error divided by the squared range of each unknown, a pure number.
"""

from __future__ import annotations

#: the unit of an image MSE between frames of pixel values in [0, 1] (say the range in a title)
IMAGE_MSE_UNIT = "pixel value²"
#: what a unitless quantity shows in its axis label
DIMENSIONLESS = "dimensionless"


def with_unit(quantity: str, unit: str) -> str:
    """``"quantity (unit)"``; an empty unit reads as dimensionless."""
    return f"{quantity} ({unit or DIMENSIONLESS})"
