"""Findings in words: one sentence per :class:`~physbench.discover.results.Finding`, for the text
verdict, the JSON's ``text`` field and the HTML report; likewise the explanations a recording
cannot tell apart (:class:`~physbench.discover.results.Ambiguity`) and what would tell them apart,
and the setup's priors (:class:`~physbench.discover.results.Prior`). Only the numbers of the
finding go into the sentence; nothing here computes a statistic."""

from __future__ import annotations

import math
from collections.abc import Callable

from physbench.discover.results import Ambiguity, Finding, Prior

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


def _start(f: Finding) -> str:
    vec = ", ".join(f"{k.removesuffix('0')} {x:+.3g}" for k, x in f.values.items() if k[0] == "v")
    b = f.body
    return (
        f"{b}: the scene starts it at rest, but over its first {f.values['seconds']:.2g} s it "
        f"moves at {vec} m/s against the model ({abs(f.size) / f.stderr:.0f} standard errors): "
        "the recording starts after its release, or the start is wrong; fit its start "
        f"(nuisance {b}.x0 {b}.y0 {b}.vx0 {b}.vy0) or give the scene its velocity"
    )


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
    "start": _start,
    "envelope": _envelope,
    "period": _period,
    "centre": _centre,
}


# --------------------------------------------------------------------------- rivals and priors

#: Degeneracies by construction (:func:`physbench.discover.equivalence.degeneracies`), in words.
DEGENERACIES = {
    "g": "in free flight a length-scale error, a clock error and a change of g are one and the "
    "same uniform acceleration (with initial speeds to match)",
    "tilt": "a turn of the axes tilts g, which is the same as a horizontal uniform force",
    "angle": "for an angle measured alone, a turn of the axes is an offset of the angle",
}
#: The measurement causes each degeneracy involves besides those named (so that what would tell
#: them apart names their references too).
DEGENERATE_WITH = {
    "g": ("calibration_scale", "clock_scale"),
    "tilt": ("axis_rotation",),
    "angle": ("axis_rotation", "sensor_offset"),
}
#: What would tell a physical effect apart from other explanations of the same data.
PHYSICAL_SEPARATORS = {
    "constant_force": "bodies of other masses, or a force of known size (a kick), in the same "
    "recording (a force accelerates each body by F/m, a measurement error all alike)",
    "table_tilt": "a level on the table, or a body that runs in other directions",
    "linear_drag": "a longer flight or faster throws, where the drag laws differ",
    "quadratic_drag": "a longer flight or faster throws, where the drag laws differ",
    "rolling_resistance": "a body that comes to rest, or runs in other directions",
    "joint_viscous_damping": "swings over a wider range of amplitudes",
    "joint_coulomb_friction": "swings over a wider range of amplitudes",
    "joint_quadratic_damping": "swings over a wider range of amplitudes",
    "velocity_dependent_restitution": "impacts over a wider range of speeds",
}


def separator(name: str) -> str:
    """What would tell the registered effect ``name`` apart from other explanations: for a
    measurement cause the reference that fixes it, for a physical effect the data that would."""
    from physbench.discover.candidates import REFERENCES

    for effect, reference in REFERENCES.values():
        if effect == name:
            return reference
    return PHYSICAL_SEPARATORS.get(name, "more data where their predictions differ")


def separators(a: Ambiguity) -> list[str]:
    """What would tell the explanations of ``a`` apart, one entry per piece of evidence with the
    effects it pins: ``"<what> (<effect>, ...)"``."""
    names = [n for member in a.members for n in member]
    names += [n for code in a.degeneracies for n in DEGENERATE_WITH.get(code, ())]
    by: dict[str, list[str]] = {}
    for n in dict.fromkeys(names):
        by.setdefault(separator(n), []).append(n)
    return [f"{what} ({', '.join(ns)})" for what, ns in by.items()]


def ambiguity_lines(a: Ambiguity, unit: str) -> list[str]:
    """The set of explanations of ``a`` in words: each with its held-out error and how much
    better the named cause predicts it (``z``, in standard deviations of the noise), the
    degeneracies by construction, what would tell them apart, and whether a physical cause is
    named alone."""
    lines = [
        "this recording cannot tell these explanations apart (held-out error; how much better "
        "the first predicts, in standard deviations of the noise):",
        f"  - {a.name:<36} {a.heldout_error:.4g} {unit}",
    ]
    for r in a.rivals:
        if r.same:  # z of a difference smaller than the noise says nothing worth printing
            how = "the same predictions"
        else:
            how = f"z {r.z:+.1f}" if math.isfinite(r.z) else "not comparable"
        lines.append(f"  - {' + '.join(r.names):<36} {r.heldout_error:.4g} {unit}  ({how})")
    lines += [f"by construction: {DEGENERACIES[code]}" for code in a.degeneracies]
    lines.append("what would tell them apart: " + "; ".join(separators(a)))
    if not a.measurement and any(r.measurement for r in a.rivals):
        lines.append(
            f"so {a.name} is not named alone: a measurement error explains the data as well"
        )
    return lines


def _percent(x: float) -> str:
    return f"{abs(x):.3g} %"


def prior_text(p: Prior) -> str:
    """The prior ``p`` in words, starting with its body's name."""
    v = p.values
    if p.kind == "level_table":
        return (
            f"{p.body}: a body on a level table feels no uniform pull; {v['accel']:.3g} m/s² "
            f"({p.effect}) is what a table sloping {1000 * v['slope']:.3g} mm per metre gives"
        )
    scale, clock = 100 * v["scale"], 100 * v["clock"]
    return (
        f"{p.body}: in still air no horizontal constant force acts on a free body; the "
        f"horizontal part of {p.effect}, {v['horizontal']:+.3g} m/s², is what axes turned by "
        f"{math.degrees(v['turn']):+.2g}° give (or a wind). And g is known: its vertical part, "
        f"{v['vertical']:+.3g} m/s² ({_percent(100 * v['vertical'] / v['g'])} of g), is what a "
        f"length scale {_percent(scale)} {'long' if scale > 0 else 'short'} or a clock "
        f"{_percent(clock)} {'slow' if clock > 0 else 'fast'} gives"
    )
