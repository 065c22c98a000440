"""The verdict of a discovery as readable text and as JSON.

JSON layout (``to_json``): ``{"base": {...}, "candidates": [{"effect", "params", "heldout_error",
"gain", "criterion", ...}, ...], "causes": [names in order], "gain": number, ...}`` plus the final
model, the diagnostics, the residual breakdowns, the split and the settings. ``gain`` is
``1 - heldout(final) / heldout(base)``; ``criterion`` is the BIC on the fitted part.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

from physbench.discover.intervals import LEVEL
from physbench.discover.phrasing import describe
from physbench.errors import counted

if TYPE_CHECKING:
    from physbench.discover.results import CandidateResult, Discovery, Finding

#: Findings shown in the text verdict.
MAX_FINDINGS = 8


def _unit(name: str, param: str) -> str:
    """The unit of parameter ``param`` of the registered effect ``name`` ("" when unknown)."""
    from physbench.errors import UnknownNameError
    from physbench.plugins import get_registry

    try:
        return get_registry().get("effect", name).param(param).unit
    except UnknownNameError:
        return ""


def format_interval(
    value: float, interval: tuple[float, float] | None, unit: str = "", *, words: bool = True
) -> str:
    """``value`` with its 90 % interval, rounded to the interval's precision:
    ``0.30 N·m (90 % interval [0.27, 0.33])``, or ``0.30 [0.27, 0.33] N·m`` without ``words``;
    the bare value (and unit) when there is no interval."""
    u = f" {unit}" if unit else ""
    lo, hi = interval if interval is not None else (math.nan, math.nan)
    half = (hi - lo) / 2
    if not (math.isfinite(lo) and math.isfinite(hi)) or half <= 0:
        return f"{value:.4g}{u}"
    digits = max(0, 1 - math.floor(math.log10(half))) if half < 1 else 0
    if digits >= 8 or 0 < abs(value) < 1e-3:
        nums = [f"{x:.3g}" for x in (value, lo, hi)]
    else:
        nums = [f"{x:.{digits}f}" for x in (value, lo, hi)]
    band = f"[{nums[1]}, {nums[2]}]"
    return f"{nums[0]}{u} ({LEVEL * 100:g} % interval {band})" if words else f"{nums[0]} {band}{u}"


def params_text(c: CandidateResult, *, words: bool = True) -> str:
    """``c``'s parameters with their 90 % intervals and units (in words, or compact for the
    table)."""
    parts = []
    for k, v in c.params.items():
        u = _unit(c.name, k)
        parts.append(f"{k} = {format_interval(v, c.intervals.get(k), u, words=words)}")
    return ", ".join(parts)


def bound_caveat(c: CandidateResult) -> str:
    """Why the magnitude of ``c`` is not a measurement when a fit left parameters at an end of
    their range ("" when none)."""
    if not c.at_bound:
        return ""
    parts = []
    for k in c.at_bound:
        v = c.params[k]
        u = _unit(c.name, k)
        more = "larger" if v > 0 else "smaller"
        parts.append(f"{k} = {v:.4g}{(' ' + u) if u else ''} (the true value may be {more})")
    return (
        "at its bound: "
        + ", ".join(parts)
        + "; the fit could not go further, so this magnitude is not a measurement"
    )


def text(disc: Discovery) -> str:
    """The readable verdict: what is wrong, the cause, its magnitude, the gain, and a table of every
    candidate."""
    u = disc.unit
    lines = []
    runs = ", ".join(r.name for r in disc.runs[:6]) + (" ..." if len(disc.runs) > 6 else "")
    lines.append(
        f"discovery on {counted(len(disc.runs), 'run')} [{runs}] with {disc.engine}; "
        f"{disc.split.describe(disc.runs)}"
    )
    b = disc.base
    lines.append(
        f"base model: fit error {b.fit.rms:.4g} {u}, held-out error {b.heldout:.4g} {u} "
        f"({b.fit.k} fitted parameters, {b.fit.n} fitted and {b.heldout_n} held-out residuals)"
    )
    shown = {k: v for k, v in b.summary()["params"].items()}
    units = {p.key: p.unit for p in b.model.params}
    if shown:
        lines.append(
            "  fitted: "
            + ", ".join(
                f"{k} = {format_interval(v, b.fit.intervals.get(k), units.get(k, ''))}"
                for k, v in shown.items()
            )
        )
    lines.append("")
    lines.append("what is wrong with the base model:")
    fs = disc.findings.get("base", [])
    if fs:
        for f in fs[:MAX_FINDINGS]:
            hint = f"  [-> {', '.join(f.suggests)}]" if f.suggests else ""
            lines.append(f"  - {describe(f)}{hint}")
        if len(fs) > MAX_FINDINGS:
            lines.append(f"  - ... {len(fs) - MAX_FINDINGS} more in the JSON")
    else:
        lines.append("  - no summary statistic stands out from the noise")
    bd = disc.breakdowns.get("base")
    if bd is not None and bd.per_event:
        for body, ev in list(bd.per_event.items())[:6]:
            cells = ", ".join(f"{e} {v:.3g}" for e, v in ev.items())
            lines.append(f"  - residual RMS of {body} by event ({u}): {cells}")
    lines.append("")
    if disc.causes:
        lines.append(
            "cause" + ("s" if len(disc.causes) > 1 else "") + " found (in the order added):"
        )
        for i, c in enumerate(disc.cause_results, 1):
            lines.append(
                f"  {i}. {c.effect}: {params_text(c)}  (held-out gain {c.gain:+.1%} over the "
                "model before it, "
                f"ΔBIC {c.delta_criterion:+.1f})"
            )
            if c.at_bound:
                lines.append(f"     {bound_caveat(c)}")
            alts = disc.alternatives.get(c.effect, [])
            if alts:
                lines.append(
                    f"     about as good on held-out data: {', '.join(alts)} (the data hardly "
                    "tell them apart)"
                )
            if c.fixed:
                lines.append(
                    "     not visible in the data, kept fixed: "
                    + ", ".join(f"{k} = {v:.4g}" for k, v in c.fixed.items())
                )
        f = disc.final
        lines.append(
            f"extended model: held-out error {f.heldout:.4g} {u} (base {b.heldout:.4g}); "
            f"gain = 1 - extended/base = {disc.gain:.1%}"
        )
    else:
        best = min(disc.candidates, key=lambda c: c.heldout_error, default=None)
        why = (
            f"; best was {best.effect} with held-out gain {best.gain:+.1%}, "
            f"ΔBIC {best.delta_criterion:+.1f}"
            + (f" ({bound_caveat(best)})" if best.at_bound else "")
            if best is not None
            else ""
        )
        lines.append(
            "no cause found: no candidate improves the held-out error by >= "
            f"{disc.settings.min_gain:.0%} with ΔBIC <= -{disc.settings.min_delta_bic:g}{why}. "
            "The base model explains the data as well as any extension."
        )
    lines.append("")
    lines.append(table(disc))
    if disc.skipped:
        lines.append("not tried: " + "; ".join(f"{n} ({why})" for n, why in disc.skipped))
    return "\n".join(lines)


def table(disc: Discovery) -> str:
    """Every candidate fit, one row each."""
    u = disc.unit
    head = (
        f"{'round':>5}  {'effect':<32} {'held-out (' + u + ')':>18} {'gain':>8} {'ΔBIC':>9}  "
        "verdict   parameters"
    )
    rows = [head, "-" * len(head)]
    rows.append(f"{0:>5}  {'base':<32} {disc.base.heldout:>18.5g} {'':>8} {'':>9}")
    for c in disc.candidates:
        verdict = "CHOSEN" if c.chosen else ("signif." if c.significant else "-")
        if c.at_bound:
            verdict += "*"
        rows.append(
            f"{c.round:>5}  {c.effect:<32} {c.heldout_error:>18.5g} {c.gain:>+8.1%} "
            f"{c.delta_criterion:>+9.1f}  "
            f"{verdict:<8}  {params_text(c, words=False)}"
        )
    if any(c.at_bound for c in disc.candidates):
        rows.append("* a parameter at the end of its range: the true value may lie beyond it")
    return "\n".join(rows)


def _clean(v: Any) -> Any:
    if isinstance(v, float):
        return v if math.isfinite(v) else None
    if isinstance(v, dict):
        return {str(k): _clean(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [_clean(x) for x in v]
    return v


def to_dict(disc: Discovery) -> dict[str, Any]:
    """The JSON-ready verdict."""
    return _clean(
        {
            "base": disc.base.summary(),
            "candidates": [c.to_dict() for c in disc.candidates],
            "causes": list(disc.causes),
            "gain": disc.gain,
            "final": disc.final.summary(),
            "alternatives": disc.alternatives,
            "engine": disc.engine,
            "unit": disc.unit,
            "runs": [
                {
                    "name": r.name,
                    "scene": r.scene.name,
                    "kind": r.kind,
                    "source": r.source,
                    "t_end": r.t_end,
                }
                for r in disc.runs
            ],
            "split": {
                "kind": disc.split.kind,
                "fraction": disc.split.fraction,
                "description": disc.split.describe(disc.runs),
                "train_runs": [disc.runs[i].name for i in disc.split.train_runs],
                "test_runs": [disc.runs[i].name for i in disc.split.test_runs],
            },
            "findings": {k: [finding_dict(f) for f in v] for k, v in disc.findings.items()},
            "residuals": {k: v.to_dict() for k, v in disc.breakdowns.items()},
            "skipped": [{"effect": n, "reason": r} for n, r in disc.skipped],
            "settings": {
                k: (list(v) if isinstance(v, tuple) else v)
                for k, v in asdict(disc.settings).items()
            },
            "seconds": disc.seconds,
        }
    )


def finding_dict(f: Finding) -> dict[str, Any]:
    """One finding in the JSON: where, the sentence, the numbers and the effects it points at."""
    return {
        "kind": f.kind,
        "run": f.run,
        "body": f.body,
        "text": describe(f),
        "values": {k: float(v) for k, v in f.values.items()},
        "suggests": list(f.suggests),
    }


def to_json(disc: Discovery, **kwargs: Any) -> str:
    return json.dumps(to_dict(disc), **kwargs)
