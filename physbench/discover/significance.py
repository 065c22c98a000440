"""When a candidate effect is a cause: the judgement of one candidate fit against the model it
extends.

A candidate is *significant* when both hold, against the model it extends:

* held-out gain ``1 - heldout(extended) / heldout(current) >= min_gain``, and
* ``ΔBIC = BIC(extended) - BIC(current) <= -min_delta_bic`` on the fitted part
  (``BIC = n ln(SSR/n) + k ln n``).
"""

from __future__ import annotations

from dataclasses import replace

from physbench.discover.results import CandidateResult, Scored
from physbench.discover.settings import Settings


def judge(c: CandidateResult, current: Scored, base: Scored, settings: Settings) -> CandidateResult:
    """``c`` with its gains (against ``current`` and against ``base``), ΔBIC, significance and
    the reasons it is not significant, judged against ``current`` (which becomes its
    ``previous``)."""
    gain = 1.0 - c.heldout_error / current.heldout if current.heldout > 0 else 0.0
    gain_vs_base = 1.0 - c.heldout_error / base.heldout if base.heldout > 0 else 0.0
    delta = c.criterion - current.bic
    why = []
    if gain < settings.min_gain:
        why.append(f"held-out gain {gain:+.1%} < {settings.min_gain:.0%}")
    if delta > -settings.min_delta_bic:
        why.append(f"ΔBIC {delta:+.1f} > -{settings.min_delta_bic:g}")
    return replace(
        c,
        previous=current,
        gain=gain,
        gain_vs_base=gain_vs_base,
        delta_criterion=delta,
        significant=bool(gain >= settings.min_gain and delta <= -settings.min_delta_bic),
        note="; ".join(why),
    )
