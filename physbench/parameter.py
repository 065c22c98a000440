r"""The one description of a named, bounded, unit-carrying quantity.

A scene's unknown (``ball.mass``), an effect's parameter (``linear_drag.c``) and a parameter that
discovery fits (``ball.vy0``) are all :class:`Parameter`\ s: ``name`` is the bare name, ``owner``
the body, effect key or force it belongs to, and :attr:`Parameter.key` is ``"<owner>.<name>"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace


@dataclass(frozen=True)
class Parameter:
    """A named parameter that lies in ``[low, high]``, in ``unit``.

    ``owner`` is what it belongs to (a body for a scene's unknown, an effect's key for an effect's
    parameter); an effect class declares its parameters without one and each instance qualifies
    them with its key (:meth:`owned_by`). ``default`` is the value used when none is given
    (``None``: the owner decides, e.g. a body's own mass). ``extensible``: the range is a typical
    span, not a physical limit (a drag coefficient, a friction torque), so a fit that reaches its
    high end, or a nonzero low end, may widen it (:meth:`widened`).
    """

    name: str
    low: float
    high: float
    owner: str = ""
    unit: str = ""
    default: float | None = None
    doc: str = ""
    extensible: bool = False

    @property
    def key(self) -> str:
        """``"<owner>.<name>"``, or the bare name for a declaration without owner."""
        return f"{self.owner}.{self.name}" if self.owner else self.name

    @property
    def width(self) -> float:
        return self.high - self.low

    def owned_by(self, owner: str) -> Parameter:
        """This parameter qualified by ``owner`` (an effect instance's key, a body)."""
        return replace(self, owner=owner)

    def widened(self, factor: float = 10.0) -> Parameter:
        """This parameter with its nonzero ends moved ``factor`` times further from zero."""
        low = self.low * factor if self.low < 0 else self.low
        high = self.high * factor if self.high > 0 else self.high
        return replace(self, low=low, high=high)

    def contains(self, value: float, *, tol: float = 0.0) -> bool:
        """Whether ``value`` is a finite number inside the range (``tol`` of slack at both ends)."""
        return math.isfinite(value) and self.low - tol <= value <= self.high + tol

    def describe(self) -> str:
        """``"[low, high] unit"`` for error messages."""
        return f"[{self.low:g}, {self.high:g}] {self.unit}".rstrip()
