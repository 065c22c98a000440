"""When a candidate effect is a cause: the judgement of one candidate fit against the model it
extends.

A candidate is *significant* when both hold, against the model it extends:

* held-out gain ``1 - heldout(extended) / heldout(current) >= min_gain``, where both held-out
  errors (RMS) are first put in quadrature with the measurement floor (:func:`measurement_floor`:
  a disagreement smaller than what the sensor can tell does not count), and
* ``ΔBIC = BIC(extended) - BIC(current) <= -min_delta_bic`` on the fitted part
  (``BIC = n ln(SSR/n) + k ln n``).

A measurement effect (a sensor's bias, a calibration's scale, ...) is not a cause when the
largest change it makes to a recorded position and angle is within the accuracy the recordings
state (:func:`within_accuracy`): the tracker's own error could make it, however well it fits. A
bouncing ball on the second camera was tracked 0.24 px off on average, towards its light, and a
sensor offset of 0.9 mm came out significant on data that states 2.9 mm.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

from physbench.discover.results import CandidateResult, Scored
from physbench.discover.settings import Settings

if TYPE_CHECKING:
    from physbench.discover.model import Problem


def measurement_floor(problem: Problem | None, settings: Settings) -> float:
    """The accuracy below which the data cannot tell a model wrong: ``settings.floor`` when
    given, else the largest accuracy the recordings of ``problem`` state (a tracker states its
    own; 0 for data that states none): their ``angle_accuracy`` (rad) where every recording
    measured angles only, their ``accuracy`` (m) otherwise."""
    if settings.floor is not None:
        return float(settings.floor)
    if problem is None:
        return 0.0
    recordings = [r.recording for r in problem.runs if r.recording is not None]
    if recordings and all(rec.measured == ("angle",) for rec in recordings):
        return max(rec.angle_accuracy for rec in recordings)
    return max((rec.accuracy for rec in recordings), default=0.0)


def within_accuracy(c: CandidateResult, problem: Problem | None, settings: Settings) -> str:
    """Why measurement candidate ``c`` could be the data's own error: its :attr:`~physbench.
    discover.results.CandidateResult.shift` within the recordings' stated accuracy (position
    and angle; :func:`measurement_floor` where ``settings.floor`` is given); ``""`` where it is
    not, where nothing states an accuracy, or for an effect on the motion."""
    if c.shift is None or problem is None:
        return ""
    recordings = [r.recording for r in problem.runs if r.recording is not None]
    position = max((rec.accuracy for rec in recordings), default=0.0)
    angle = max((rec.angle_accuracy for rec in recordings), default=0.0)
    if settings.floor is not None:
        position = angle = float(settings.floor)
    moved, turned = c.shift
    if position <= 0 or moved > position or (turned > 0 and turned > angle):
        return ""
    said = f"it moves a recorded position by {moved:.2g} m at most"
    if turned > 0:
        said += f" and an angle by {turned:.2g} rad"
    return f"{said}, within the data's accuracy ({position:.2g} m): the tracker could make it"


def floored_gain(new: float, old: float, floor: float) -> float:
    """``1 - new / old`` for held-out RMS errors, each in quadrature with ``floor``."""
    old_f = math.hypot(old, floor)
    return 1.0 - math.hypot(new, floor) / old_f if old_f > 0 else 0.0


def judge(c: CandidateResult, current: Scored, base: Scored, settings: Settings) -> CandidateResult:
    """``c`` with its gains (against ``current`` and against ``base``), ΔBIC, significance and
    the reasons it is not significant, judged against ``current`` (which becomes its
    ``previous``)."""
    gain = 1.0 - c.heldout_error / current.heldout if current.heldout > 0 else 0.0
    gain_vs_base = 1.0 - c.heldout_error / base.heldout if base.heldout > 0 else 0.0
    floor = measurement_floor(current.model and current.model.problem, settings)
    counted = floored_gain(c.heldout_error, current.heldout, floor)
    delta = c.criterion - current.bic
    why = []
    if counted < settings.min_gain:
        above = f" above the data's accuracy {floor:.2g}" if floor > 0 else ""
        why.append(f"held-out gain{above} {counted:+.1%} < {settings.min_gain:.0%}")
    if delta > -settings.min_delta_bic:
        why.append(f"ΔBIC {delta:+.1f} > -{settings.min_delta_bic:g}")
    if not why and (said := within_accuracy(c, current.model and current.model.problem, settings)):
        why.append(said)
    return replace(
        c,
        previous=current,
        gain=gain,
        gain_vs_base=gain_vs_base,
        delta_criterion=delta,
        significant=not why,
        note="; ".join(why),
    )
