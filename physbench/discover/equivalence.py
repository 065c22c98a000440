"""Which explanations a recording cannot tell apart from the causes it names, and what the setup
says about them.

After the selection, each cause is set against its rivals: the other candidates of its round that
are significant themselves (they explain the data too), and, for a physical cause, the best
combination of up to two measurement causes (a beam search from the model the cause extends, each
step improving the fit at all): a length scale and a turn of the axes together tilt and stretch
``g`` in any direction, which a constant force does too, so no single measurement cause need match
it, nor explain much alone. A cause **beats** a rival when it predicts the held-out data better by
``Settings.beat_z`` standard deviations of the noise of that difference (:func:`paired`; the
noise is the final model's, :func:`noise`: the best estimate of the data's) *and* by
the margin a cause needs over the model without it (a floored held-out gain of
``Settings.min_gain``: fits of one model family that stop a little apart can differ beyond the
noise in how they extrapolate, but not by that much); a rival it does not beat explains the data
equally, and the verdict names the whole set
(:class:`~physbench.discover.results.Ambiguity`). So a physical cause is named alone only when it
beats every measurement cause.

Some sets are one and the same by construction, and are reported as such when their fits predict
the same held-out data: in free flight a length-scale error, a clock error and a change of ``g``
are one uniform acceleration (``"g"``), a turn of the axes tilts ``g`` like a horizontal uniform
force (``"tilt"``), and for an angle measured alone a turn of the axes is an angle offset
(``"angle"``).

:func:`setup_priors` states what the setup says about a uniform pull that was named: in a side
view no horizontal force acts on a ball in still air and ``g`` is known, so such a pull is what a
turn of the axes or a scale error would give; seen from above, it is a table's tilt.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from physbench.discover.candidates import CandidateSpec, is_measurement
from physbench.discover.fit import is_rough
from physbench.discover.intervals import lag1
from physbench.discover.results import (
    Ambiguity,
    CandidateResult,
    Prior,
    Rival,
    Scored,
    Selection,
)
from physbench.discover.settings import Settings
from physbench.discover.significance import floored_gain, measurement_floor
from physbench.discover.trial import try_effect
from physbench.errors import SimulationError

#: Two fits make "the same predictions" when their held-out predictions differ by less than this
#: share of the noise (RMS): fits of one and the same model family stop a little apart, and the
#: held-out part extrapolates that (a quarter of the noise between a scale and a clock error).
SAME = 0.25
#: Registered names of the uniform accelerations of a free body, and of the measurement causes
#: that are one in free flight.
UNIFORM = ("constant_force", "table_tilt")
G_LIKE = ("calibration_scale", "clock_scale", *UNIFORM)
#: Most measurement causes combined against a physical cause, and how many partial combinations
#: are carried to the next size: in free flight the camera's errors act as one uniform
#: acceleration, whose size a scale (or clock) error sets and whose direction a turn of the axes
#: does, so pairs match any uniform pull; elsewhere the selection itself finds measurement causes
#: one by one.
COMBINED = 2
BEAM = 3


def compare_explanations(
    selection: Selection, specs: Sequence[CandidateSpec], settings: Settings
) -> Selection:
    """``selection`` with the rivals of each cause (``ambiguities``) and the setup's ``priors``.
    ``specs``: the candidates of the selection (the measurement causes among them are combined
    against a physical cause)."""
    problem = selection.base.model.problem
    floor = measurement_floor(problem, settings)
    seen = noise(selection.final, floor)
    out = []
    for c in (c for c in selection.candidates if c.chosen and c.scored is not None):
        rivals = _round_rivals(c, selection.candidates, seen, floor, settings)
        if not is_measurement(c.name) and not any(r.measurement for r in rivals):
            combined = _measurement_rival(c, selection, specs, seen, floor, settings)
            if combined is not None:
                rivals.append(combined)
        if rivals:
            gravity = any(tuple(r.scene.gravity) != (0.0, 0.0) for r in problem.runs)
            out.append(
                Ambiguity(
                    c.effect,
                    c.name,
                    is_measurement(c.name),
                    c.heldout_error,
                    tuple(rivals),
                    degeneracies(c.name, rivals, gravity=gravity),
                )
            )
    return replace(selection, ambiguities=out, priors=setup_priors(selection))


def _held(s: Scored) -> np.ndarray | None:
    """The held-out residuals of ``s`` at its fitted values (None when they do not simulate)."""
    if not math.isfinite(s.heldout):
        return None
    try:
        return s.model.residuals("held", s.fit.values)
    except SimulationError:
        return None


def noise(s: Scored, floor: float = 0.0) -> tuple[float, float]:
    """The data's noise as the fitted model ``s`` sees it: its residual RMS in quadrature with the
    data's accuracy ``floor``, and the mean lag-1 autocorrelation of its held-out residuals within
    their series (0 when they do not simulate)."""
    sigma = math.hypot(s.fit.rms, floor)
    r = _held(s)
    labels = s.model.problem.series("held")
    if r is None or labels.shape != r.shape or r.size == 0:
        return sigma, 0.0
    rhos, sizes = [], []
    for lab in np.unique(labels):
        part = r[labels == lab]
        rhos.append(lag1(part))
        sizes.append(part.size)
    return sigma, float(np.average(rhos, weights=sizes))


def paired(a: Scored, b: Scored, sigma: float, rho: float = 0.0) -> tuple[float, bool]:
    """How much better ``a`` predicts the held-out data than ``b`` (``z``, > 0 when ``a`` is
    better), and whether they predict the same.

    Both are compared on the same held-out samples, so the noise cancels but for its projection
    on the difference ``d`` of their predictions: ``SSR(b) - SSR(a)`` has standard deviation
    ``2 σ |d|`` under noise ``σ``; noise correlated in time (lag-1 ``ρ``) counts
    ``(1 - ρ) / (1 + ρ)`` times as many independent samples. ``z`` is nan when the two cannot be
    compared (a fit fails on the held-out data)."""
    ra, rb = _held(a), _held(b)
    if ra is None or rb is None or ra.shape != rb.shape or ra.size == 0:
        return math.nan, False
    d = ra - rb
    nd = float(np.linalg.norm(d))
    if not sigma > 0:
        return (math.nan, False) if nd > 0 else (0.0, True)
    same = nd / math.sqrt(d.size) <= SAME * sigma
    if nd == 0.0:
        return 0.0, True
    z = float(rb @ rb - ra @ ra) / (2.0 * sigma * nd) * math.sqrt((1 - rho) / (1 + rho))
    return z, same


def beats(c: CandidateResult, rival: Rival, floor: float, settings: Settings) -> bool:
    """Whether cause ``c`` predicts the held-out data better than ``rival`` beyond the noise
    (``beat_z``) and by the margin a cause needs (``min_gain``, floored)."""
    gain = floored_gain(c.heldout_error, rival.heldout_error, floor)
    return bool(rival.z >= settings.beat_z and gain >= settings.min_gain)


def _rival(
    c: CandidateResult,
    effects: Sequence[CandidateResult],
    scored: Scored,
    noise: tuple[float, float],
) -> Rival:
    z, same = paired(c.scored, scored, *noise) if c.scored is not None else (math.nan, False)
    return Rival(
        tuple(e.effect for e in effects),
        tuple(e.name for e in effects),
        all(is_measurement(e.name) for e in effects),
        scored.heldout,
        z,
        same,
    )


def _round_rivals(
    c: CandidateResult,
    candidates: Sequence[CandidateResult],
    noise: tuple[float, float],
    floor: float,
    settings: Settings,
) -> list[Rival]:
    """The candidates of ``c``'s round that explain the data (significant) and that ``c`` does
    not beat."""
    out = []
    for r in candidates:
        if r is c or r.round != c.round or not r.significant or r.scored is None:
            continue
        rival = _rival(c, [r], r.scored, noise)
        if not beats(c, rival, floor, settings):  # nan (not comparable) keeps the rival
            out.append(rival)
    return sorted(out, key=lambda r: r.heldout_error)


def _measurement_rival(
    c: CandidateResult,
    selection: Selection,
    specs: Sequence[CandidateSpec],
    noise: tuple[float, float],
    floor: float,
    settings: Settings,
) -> Rival | None:
    """A combination of up to :data:`COMBINED` measurement causes, added to the model ``c``
    extends, that explains the data as well as ``c``; None when none does. A beam search over the
    measurement causes that improve the fit at all alone (none need be a cause by itself: a scale
    error and a turn of the axes each explain only a part of a tilted, stretched ``g``, and a turn
    of a fraction of a degree does not pay for its parameter alone): the :data:`BEAM` that predict
    the held-out data best, then each of them with every other."""
    previous = c.previous
    if previous is None or c.scored is None:
        return None
    present = {e.key for e in previous.model.effects} | {c.effect}
    pool = [s for s in specs if is_measurement(s.name) and s.label not in present]
    rough = is_rough(previous.model.problem.runs)
    done = {
        r.effect: r for r in selection.candidates if r.round == c.round and r.previous is previous
    }
    singles = [
        done.get(s.label)
        or try_effect(previous, s, settings, base=selection.base, round=c.round, quick=rough)
        for s in pool
    ]
    useful = _best([[r] for r in singles if isinstance(r, CandidateResult)], len(pool))
    beam = useful[: 1 if rough else BEAM]
    pool = [s for s in pool if any(ch[0].effect == s.label for ch in useful)]
    for depth in range(1, min(COMBINED, settings.max_causes) + 1):
        for chain in beam:
            assert chain[-1].scored is not None
            rival = _rival(c, chain, chain[-1].scored, noise)
            if not beats(c, rival, floor, settings):
                return rival
        if depth == min(COMBINED, settings.max_causes):
            return None
        longer, tried = [], set()
        for chain in beam:
            assert chain[-1].scored is not None
            for s in pool:
                key = frozenset([*(r.effect for r in chain), s.label])
                if len(key) == len(chain) or key in tried:
                    continue
                tried.add(key)
                r = try_effect(chain[-1].scored, s, settings, base=selection.base, round=c.round)
                if isinstance(r, CandidateResult):
                    longer.append([*chain, r])
        beam = _best(longer, BEAM)
    return None


def _improves(r: CandidateResult) -> bool:
    """Whether the fit of ``r`` is better than that of the model it extends at all."""
    return (
        r.scored is not None
        and r.previous is not None
        and r.scored.fit.ssr < r.previous.fit.ssr * (1 - 1e-9)
    )


def _best(chains: list[list[CandidateResult]], width: int) -> list[list[CandidateResult]]:
    """The ``width`` chains that predict the held-out data best, each last step improving the
    fit, one per set of effects."""
    seen: set[frozenset[str]] = set()
    out = []
    for chain in sorted(chains, key=lambda ch: (ch[-1].heldout_error, ch[-1].criterion)):
        key = frozenset(r.effect for r in chain)
        if not _improves(chain[-1]) or key in seen:
            continue
        seen.add(key)
        out.append(chain)
    return out[:width]


def degeneracies(name: str, rivals: Sequence[Rival], *, gravity: bool) -> tuple[str, ...]:
    """The known degeneracies by construction among ``name`` and the rivals that predict the same
    as it: ``"g"`` (scale, clock and a uniform acceleration, with gravity in the plane), ``"tilt"``
    (a turn of the axes and a uniform acceleration, with gravity in the plane), ``"angle"`` (a
    turn of the axes and a sensor's offset)."""
    names = {name} | {n for r in rivals if r.same for n in r.names}
    out = []
    if gravity and len(names & set(G_LIKE)) >= 2:
        out.append("g")
    if gravity and "axis_rotation" in names and names & {*UNIFORM, *G_LIKE}:
        out.append("tilt")
    if {"axis_rotation", "sensor_offset"} <= names:
        out.append("angle")
    return tuple(out)


# --------------------------------------------------------------------------- priors


def setup_priors(selection: Selection) -> list[Prior]:
    """What the setup says about each uniform pull named as a cause, body by body (free bodies
    only): in a side view its horizontal and vertical parts, with the turn of the axes and the
    scale error that would give them; seen from above, the table's slope it takes."""
    problem = selection.base.model.problem
    scene = problem.runs[0].scene
    jointed = {j.a for j in scene.joints} | {j.b for j in scene.joints if j.b is not None}
    out = []
    for c in selection.candidates:
        if not c.chosen or c.name not in UNIFORM:
            continue
        values = {k: c.params.get(k, c.fixed.get(k, 0.0)) for k in ("fx", "fy", "ax", "ay")}
        for body in scene.bodies:
            if body.name in jointed or not _acts_on(c, body.name):
                continue
            if c.name == "constant_force":
                a = np.array([values["fx"], values["fy"]]) / body.mass
            else:
                a = np.array([values["ax"], values["ay"]])
            out.append(_prior(c.effect, body.name, a, np.asarray(scene.gravity, dtype=float)))
    return out


def _acts_on(c: CandidateResult, body: str) -> bool:
    if c.scored is None:
        return True
    eff = next((e for e in c.scored.model.effects if e.key == c.effect), None)
    return eff is None or eff.bodies is None or body in eff.bodies


def _prior(effect: str, body: str, a: np.ndarray, g: np.ndarray) -> Prior:
    gn = float(np.linalg.norm(g))
    if gn == 0.0:
        slope = float(np.linalg.norm(a)) / 9.81
        return Prior(
            "level_table", effect, body, {"accel": float(np.linalg.norm(a)), "slope": slope}
        )
    down = g / gn
    across = np.array([-down[1], down[0]])
    vertical = float(-a @ down)  # up: against gravity
    horizontal = float(a @ across)
    seen = g + a
    stretch = float(np.linalg.norm(seen)) / gn
    return Prior(
        "still_air",
        effect,
        body,
        {
            "horizontal": horizontal,
            "vertical": vertical,
            "g": gn,
            "turn": math.atan2(horizontal, gn - vertical),
            "scale": stretch - 1.0,
            "clock": math.sqrt(stretch) - 1.0,
        },
    )
