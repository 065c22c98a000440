"""Findings in words: one sentence per :class:`~physbench.discover.results.Finding`, for the text
verdict, the JSON's ``text`` field and the HTML report. Only the numbers of the finding go into
the sentence; nothing here computes a statistic."""

from __future__ import annotations

from collections.abc import Callable

from physbench.discover.results import Finding

#: How a free-flight loss scales with speed, in words.
SPEED_LAWS = {
    "constant": "about constant (a rolling-resistance-like loss)",
    "linear": "about proportional to the speed (linear drag)",
    "quadratic": "about proportional to the squared speed (quadratic drag)",
}
#: How the loss per swing scales with the amplitude, in words.
SWING_LAWS = {
    "constant": "about constant (dry, Coulomb-like friction)",
    "linear": "about proportional to the amplitude (viscous)",
    "quadratic": "about proportional to the squared amplitude (air-drag-like)",
}


def describe(f: Finding) -> str:
    """The sentence for ``f``, starting with its body's name."""
    return _PHRASES[f.kind](f)


def _free_flight(f: Finding) -> str:
    a_ex, v = f.size, f.values
    if a_ex < 0:
        return (
            f"{f.body}: in free flight the observed speed falls {-a_ex:.3g} m/s² slower "
            "than simulated (the model loses too much speed)"
        )
    vbar = v["mean_speed"]
    text = (
        f"{f.body}: in free flight the observed speed falls {a_ex:.3g} ± {f.stderr:.2g} m/s² "
        f"faster than simulated ({a_ex / vbar:.1%} of the mean speed per second)"
        if vbar > 0
        else f"{f.body}: observed speed falls faster"
    )
    if "speed_exponent" in v:
        law = SPEED_LAWS[f.trend]
        text += f"; the excess grows like speed^{v['speed_exponent']:.1f}: {law}"
    return text


def _impacts(f: Finding) -> str:
    v = f.values
    text = (
        f"{f.body}: across {int(v['impacts'])} impacts the observed speed keeps "
        f"{v['observed_speed_ratio']:.0%} where the model keeps {v['simulated_speed_ratio']:.0%}"
    )
    if f.trend:
        grows = "grows" if f.trend == "growing" else "shrinks"
        text += (
            f"; the shortfall {grows} with the impact speed ({v['shortfall_per_mps']:+.2g} per m/s)"
        )
    return text + (
        " (energy lost beyond what restitution allows)"
        if f.size > 0
        else " (the model loses too much at impacts)"
    )


def _drift(f: Finding) -> str:
    vec = ", ".join(f"{k.removeprefix('a')} {a:+.3g}" for k, a in f.values.items())
    return (
        f"{f.body}: the residual drifts as if the model missed a uniform acceleration ({vec} m/s²)"
    )


def _offset(f: Finding) -> str:
    field = f.statistic.removeprefix("d")
    unit = "rad" if field == "angle" else "m"
    return f"{f.body}: observed {field} sits {f.size:+.3g} {unit} from the simulated one throughout"


def _envelope(f: Finding) -> str:
    v = f.values
    return (
        f"{f.body}: the observed amplitude falls from {v['observed_first']:.3g} to "
        f"{v['observed_last']:.3g} rad over {int(v['half_swings']) - 1} half swings, the "
        f"simulated one from {v['simulated_first']:.3g} to {v['simulated_last']:.3g}; the loss "
        f"per swing is {SWING_LAWS[f.trend]}"
    )


def _period(f: Finding) -> str:
    return f"{f.body}: the observed period is {f.size:.4f} × the simulated one"


def _centre(f: Finding) -> str:
    return f"{f.body}: the observed swing is centred {f.size:+.3g} rad from the simulated one"


_PHRASES: dict[str, Callable[[Finding], str]] = {
    "free_flight": _free_flight,
    "impacts": _impacts,
    "drift": _drift,
    "offset": _offset,
    "envelope": _envelope,
    "period": _period,
    "centre": _centre,
}
