"""Summary statistics of the disagreement between a fitted model and the data that point at causes:
speed lost in free flight beyond the model (and how that loss scales with speed), energy lost at
impacts beyond the restitution, a uniform acceleration the model lacks, a constant offset, and the
amplitude envelope, period and centre of oscillations; and one that points at the setup instead:
a body the scene starts at rest that the recording shows moving from its first samples.

Each statistic becomes a :class:`~physbench.discover.results.Finding`: numbers (where it was
measured, the statistic, its size, how it scales) and the effects it points at;
:mod:`physbench.discover.phrasing` puts it into words. They guide the reader and the choice of
candidates to fit in full; the decision is made by the candidate fits
(:mod:`physbench.discover.select`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from physbench.discover.residuals import EVENTS, Breakdown, Layout, breakdown, frame_events
from physbench.discover.results import Diagnosis, Finding
from physbench.recording import Recording, Track

if TYPE_CHECKING:
    from physbench.discover.model import Model
    from physbench.discover.results import Scored
    from physbench.scene import Scene
    from physbench.trajectory import Trajectory

#: A statistic is reported when it is this many standard errors from zero.
Z_REPORT = 3.0
#: The first seconds of a recording in which a body the scene starts at rest must not move,
#: and how far they may stretch to hold 5 samples (a slower clip is not judged).
START_WINDOW = 0.3
START_LIMIT = 0.5


@dataclass(frozen=True, eq=False)
class RunView:
    """One run seen through one fitted model: the simulation and the data side by side."""

    name: str
    scene: Scene
    traj: Trajectory  # as the engine simulated it
    measured: Trajectory  # after the measurement effects (the data's clock)
    recording: Recording | None
    simulated: Recording | None  # the simulation sampled at the recording's times
    events: np.ndarray  # (T, N) event index per frame of ``measured``


def views(model: Model) -> list[RunView]:
    """Full-length simulations of every run with the model's current values."""
    out = []
    for i, run in enumerate(model.problem.runs):
        traj, measured = model.simulate(i, model.values)
        scene, _ = model.run_scene(i, model.values)
        sim = run.recording.sample(measured) if run.recording is not None else None
        out.append(
            RunView(
                run.name, scene, traj, measured, run.recording, sim, frame_events(scene, measured)
            )
        )
    return out


def diagnose(scored: Scored) -> Diagnosis:
    """What the fitted model of ``scored`` gets wrong: its findings and its residual breakdown per
    body, field and event, over the whole of every run."""
    vs = views(scored.model)
    return Diagnosis(findings(vs), residual_breakdown(vs))


def residual_breakdown(vs: Sequence[RunView]) -> Breakdown:
    """RMS residuals per body and field and per body and event, pooled over the runs with
    recordings."""
    parts = []
    for v in vs:
        if v.recording is None:
            continue
        lay = Layout.of_recording(v.recording, v.scene)
        r = v.recording.residuals(v.measured) * lay.weight
        k = np.clip(np.searchsorted(v.measured.times, lay.t - 1e-9), 0, v.measured.frames - 1)
        idx = np.array([v.scene.body_index(n) for n in v.recording.bodies])
        parts.append((lay, r, v.events[k, idx[lay.body]], list(v.recording.bodies)))
    return breakdown(parts)


def findings(vs: Sequence[RunView]) -> list[Finding]:
    """Every statistic that stands out from the noise, run by run and body by body."""
    out: list[Finding] = []
    for v in vs:
        if v.recording is None or v.simulated is None:
            continue
        for body in v.recording.bodies:
            i = v.scene.body_index(body)
            obs, sim = v.recording.track(body), v.simulated.track(body)
            k = np.clip(np.searchsorted(v.measured.times, obs.t - 1e-9), 0, v.measured.frames - 1)
            ev = v.events[k, i]
            jointed = any(j.a == body or j.b == body for j in v.scene.joints)
            fields = set(obs.fields) & set(v.recording.fields or obs.fields)
            if jointed and "angle" in fields:
                out += _oscillation(v.name, body, obs, sim)
                continue
            pos = [f for f in ("x", "y") if f in fields]
            if pos:
                if not jointed and _at_rest(v.scene, body):
                    out += _start(v.name, body, obs, sim, ev, pos, v.recording.accuracy)
                out += _free_flight(v.name, body, obs, sim, ev, pos)
                out += _impacts(v.name, body, obs, sim, ev, pos)
                out += _drift(v.name, body, obs, sim, pos)
            out += _offset(v.name, body, obs, sim, sorted(fields))
    return out


# --------------------------------------------------------------------------- helpers


def _speed(t: np.ndarray, tr: Track, pos: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """Speeds from successive samples (m/s) at the interval midpoints."""
    dt = np.diff(t)
    d2 = sum(np.diff(tr.values(f)) ** 2 for f in pos)
    return 0.5 * (t[1:] + t[:-1]), np.sqrt(d2) / dt


def _segments(mask: np.ndarray, min_len: int) -> list[tuple[int, int]]:
    out, i, n = [], 0, mask.size
    while i < n:
        if not mask[i]:
            i += 1
            continue
        j = i
        while j < n and mask[j]:
            j += 1
        if j - i >= min_len:
            out.append((i, j))
        i = j
    return out


def _line(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Slope, its standard error and intercept of a least-squares line."""
    a = np.stack([np.ones_like(x), x], axis=1)
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    r = y - a @ coef
    dof = max(x.size - 2, 1)
    cov = np.linalg.pinv(a.T @ a) * float(r @ r) / dof
    return float(coef[1]), float(math.sqrt(max(cov[1, 1], 0.0))), float(coef[0])


def _free_flight(
    run: str, body: str, obs: Track, sim: Track, ev: np.ndarray, pos: Sequence[str]
) -> list[Finding]:
    free = ev == EVENTS.index("free")
    tm, vo = _speed(obs.t, obs, pos)
    _, vs = _speed(obs.t, sim, pos)
    ok = free[1:] & free[:-1]
    slopes, weights, halves = [], [], []
    for i, j in _segments(ok, 8):
        s, se, _ = _line(tm[i:j], vo[i:j] - vs[i:j])
        if se > 0:
            slopes.append(s)
            weights.append(1 / se**2)
        mid = (i + j) // 2
        for a, b in ((i, mid), (mid, j)):
            if b - a >= 4:
                s2, se2, _ = _line(tm[a:b], vo[a:b] - vs[a:b])
                halves.append((float(np.mean(vs[a:b])), -s2, se2))
    if not slopes:
        return []
    w = np.asarray(weights)
    a_ex = -float(np.sum(w * np.asarray(slopes)) / w.sum())
    se = float(1 / math.sqrt(w.sum()))
    if abs(a_ex) < Z_REPORT * se:
        return []
    vbar = float(np.mean(vs[ok])) if ok.any() else math.nan
    values = {"excess_deceleration": a_ex, "stderr": se, "mean_speed": vbar}
    if a_ex < 0:  # the model loses too much speed
        return [
            Finding("free_flight", run, body, "free", "excess_deceleration", a_ex, se, "", values)
        ]
    suggests: tuple[str, ...] = ("linear_drag", "quadratic_drag", "rolling_resistance")
    trend = ""
    pts = [(v, a) for v, a, s in halves if a > 2 * s and v > 0]
    if len(pts) >= 3 and np.ptp([p[0] for p in pts]) > 0.2 * np.mean([p[0] for p in pts]):
        lv, la = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
        n_exp = float(np.polyfit(lv, la, 1)[0])
        values["speed_exponent"] = n_exp
        if n_exp < 0.5:
            suggests, trend = ("rolling_resistance",), "constant"
        elif n_exp < 1.5:
            suggests, trend = ("linear_drag",), "linear"
        else:
            suggests, trend = ("quadratic_drag",), "quadratic"
    return [
        Finding(
            "free_flight",
            run,
            body,
            "free",
            "excess_deceleration",
            a_ex,
            se,
            trend,
            values,
            suggests,
        )
    ]


def _impacts(
    run: str, body: str, obs: Track, sim: Track, ev: np.ndarray, pos: Sequence[str]
) -> list[Finding]:
    hit = ev == EVENTS.index("impact")
    if not hit.any():
        return []
    _tm, vo = _speed(obs.t, obs, pos)
    _, vs = _speed(obs.t, sim, pos)
    ratios, speeds = [], []
    for i, j in _segments(hit, 1):
        before = slice(max(0, i - 4), max(0, i - 1))
        after = slice(min(vo.size, j + 1), min(vo.size, j + 4))
        if before.stop - before.start < 2 or after.stop - after.start < 2:
            continue
        if np.any(hit[before]) or np.any(hit[after.start : after.stop + 1]):
            continue
        vb_o, va_o = float(np.mean(vo[before])), float(np.mean(vo[after]))
        vb_s, va_s = float(np.mean(vs[before])), float(np.mean(vs[after]))
        if min(vb_o, vb_s) <= 1e-6:
            continue
        ratios.append((va_o / vb_o, va_s / vb_s))
        speeds.append(vb_o)
    if len(ratios) < 2:
        return []
    r = np.asarray(ratios)
    short = r[:, 1] - r[:, 0]
    mean, se = float(short.mean()), float(short.std(ddof=1) / math.sqrt(len(short)))
    values = {
        "impacts": float(len(short)),
        "observed_speed_ratio": float(r[:, 0].mean()),
        "simulated_speed_ratio": float(r[:, 1].mean()),
    }
    if abs(mean) < max(Z_REPORT * se, 0.02):
        return []
    trend = ""
    if len(short) >= 3 and np.ptp(speeds) > 0:
        slope, sse, _ = _line(np.asarray(speeds), short)
        values["shortfall_per_mps"] = slope
        if abs(slope) > Z_REPORT * sse:
            trend = "growing" if slope > 0 else "shrinking"
    # size > 0: energy lost beyond what restitution allows; < 0: the model loses too much
    return [
        Finding(
            "impacts",
            run,
            body,
            "impact",
            "speed_ratio_shortfall",
            mean,
            se,
            trend,
            values,
            ("velocity_dependent_restitution",),
        )
    ]


def _at_rest(scene: Scene, body: str) -> bool:
    """Whether ``scene`` starts ``body`` at rest (so discovery takes its start as known: no
    initial-state nuisance is fitted for it by default)."""
    b = scene.bodies[scene.body_index(body)]
    return math.hypot(*b.velocity) == 0 and b.angular_velocity == 0


def _start(
    run: str,
    body: str,
    obs: Track,
    sim: Track,
    ev: np.ndarray,
    pos: Sequence[str],
    accuracy: float | None,
) -> list[Finding]:
    """A body the scene starts at rest that moves in the recording's first samples: the clip
    began after its release, or the scene's start is wrong. Its initial velocity against the
    model is the slope at the first sample of a cubic through the residual over the first
    :data:`START_WINDOW` s of free flight (at least 5 samples, within :data:`START_LIMIT` s).
    From rest, a missing force bends the residual like t², linear drag like t³ (both taken up
    by the cubic) and quadratic drag like t⁴; measurement errors add a constant and a t² term:
    only a start in motion moves it like t. The standard error is from the recording's stated
    accuracy where it has one, else (with at least 3 degrees of freedom) the scatter."""
    free = ev == EVENTS.index("free")
    n = int(np.argmin(free)) if not free.all() else free.size  # samples before the first event
    t = obs.t[:n] - obs.t[0]
    k = max(int(np.searchsorted(t, START_WINDOW, side="right")), 5)
    if n < k or t[k - 1] > START_LIMIT or (not accuracy and k < 7):
        return []
    t = t[:k]
    a = np.stack([np.ones_like(t), t, t * t, t**3], axis=1)
    inv = np.linalg.pinv(a.T @ a)
    vel, se = {}, {}
    for f in pos:
        r = obs.values(f)[:k] - sim.values(f)[:k]
        coef, *_ = np.linalg.lstsq(a, r, rcond=None)
        res = r - a @ coef
        var = accuracy**2 if accuracy else float(res @ res) / (k - 4)
        vel[f], se[f] = float(coef[1]), math.sqrt(var * inv[1, 1])
    if not all(math.isfinite(e) and e > 0 for e in se.values()):
        return []
    top = max(pos, key=lambda f: abs(vel[f]) / se[f])
    if abs(vel[top]) < Z_REPORT * se[top]:
        return []
    return [
        Finding(
            "start",
            run,
            body,
            "free",
            f"v{top}0",
            vel[top],
            se[top],
            "",
            {f"v{f}0": vel[f] for f in pos} | {"seconds": float(t[-1]), "samples": float(k)},
        )
    ]


def _drift(run: str, body: str, obs: Track, sim: Track, pos: Sequence[str]) -> list[Finding]:
    if len(obs) < 8:
        return []
    t = obs.t - obs.t[0]
    a = np.stack([np.ones_like(t), t, 0.5 * t * t], axis=1)
    acc, se = {}, {}
    for f in pos:
        r = sim.values(f) - obs.values(f)
        coef, *_ = np.linalg.lstsq(a, r, rcond=None)
        res = r - a @ coef
        cov = np.linalg.pinv(a.T @ a) * float(res @ res) / max(t.size - 3, 1)
        acc[f], se[f] = -float(coef[2]), float(math.sqrt(max(cov[2, 2], 0.0)))
    zs = {f: abs(acc[f]) / se[f] if se[f] > 0 else 0.0 for f in pos}
    top = max(pos, key=zs.__getitem__)
    if zs[top] < 2 * Z_REPORT:
        return []
    values = {f"a{f}": acc[f] for f in pos}
    return [
        Finding(
            "drift",
            run,
            body,
            "",
            f"a{top}",
            acc[top],
            se[top],
            "",
            values,
            ("constant_force", "table_tilt"),
        )
    ]


def _offset(run: str, body: str, obs: Track, sim: Track, fields: Sequence[str]) -> list[Finding]:
    out = []
    for f in fields:
        d = obs.values(f) - sim.values(f)
        if f == "angle":
            d = (d + math.pi) % (2 * math.pi) - math.pi
        if d.size < 8:
            continue
        mean, sd = float(d.mean()), float(d.std())
        stderr = sd / math.sqrt(d.size)
        if abs(mean) > 0.7 * math.sqrt(mean * mean + sd * sd) and abs(
            mean
        ) > Z_REPORT * sd / math.sqrt(d.size):
            out.append(
                Finding(
                    "offset",
                    run,
                    body,
                    "",
                    f"d{f}",
                    mean,
                    stderr,
                    "",
                    {f"d{f}": mean},
                    ("sensor_offset",),
                )
            )
    return out


def _oscillation(run: str, body: str, obs: Track, sim: Track) -> list[Finding]:
    from physbench.datasets.oscillation import (
        oscillation_centre,
        oscillation_periods,
        swing_peaks,
    )

    t = obs.t
    ao, asim = obs.values("angle"), sim.values("angle")
    co, cs = oscillation_centre(t, ao), oscillation_centre(t, asim)
    out: list[Finding] = []
    _, po = swing_peaks(t, ao, co)
    _, ps = swing_peaks(t, asim, cs)
    if po.size >= 4 and ps.size >= 2:
        d = po[:-1] - po[1:]  # loss per half swing
        amp = 0.5 * (po[:-1] + po[1:])
        fits = {}
        for name, basis in (
            ("coulomb", np.ones_like(amp)),
            ("viscous", amp),
            ("quadratic", amp * amp),
        ):
            c = float(basis @ d / (basis @ basis))
            fits[name] = float(np.sum((d - c * basis) ** 2))
        law = min(fits, key=fits.__getitem__)
        effect = {
            "coulomb": "joint_coulomb_friction",
            "viscous": "joint_viscous_damping",
            "quadratic": "joint_quadratic_damping",
        }[law]
        trend = {"coulomb": "constant", "viscous": "linear", "quadratic": "quadratic"}[law]
        values = {
            "observed_first": float(po[0]),
            "observed_last": float(po[-1]),
            "simulated_first": float(ps[0]),
            "simulated_last": float(ps[-1]),
            "half_swings": float(po.size),
        }
        sim_loss = float(ps[0] - ps[-1]) / max(ps.size - 1, 1)
        obs_loss = float(po[0] - po[-1]) / max(po.size - 1, 1)
        if obs_loss > 1.5 * max(sim_loss, 0.0) + 1e-4:
            out.append(
                Finding(
                    "envelope",
                    run,
                    body,
                    "jointed",
                    "loss_per_half_swing",
                    obs_loss,
                    math.nan,
                    trend,
                    values,
                    (effect,),
                )
            )
    per_o, per_s = oscillation_periods(t, ao, co), oscillation_periods(t, asim, cs)
    if per_o.size >= 2 and per_s.size >= 2:
        ratio = float(np.median(per_o) / np.median(per_s))
        spread = float(np.std(per_o) / np.sqrt(per_o.size) / np.median(per_s))
        if abs(ratio - 1) > max(Z_REPORT * spread, 0.002):
            out.append(
                Finding(
                    "period",
                    run,
                    body,
                    "jointed",
                    "period_ratio",
                    ratio,
                    spread,
                    "",
                    {"period_ratio": ratio},
                    ("clock_scale",),
                )
            )
    if abs(co - cs) > 0.005:
        out.append(
            Finding(
                "centre",
                run,
                body,
                "jointed",
                "dangle",
                co - cs,
                math.nan,
                "",
                {"dangle": co - cs},
                ("sensor_offset",),
            )
        )
    return out
