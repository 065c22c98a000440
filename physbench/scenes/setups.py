"""Scenes for one's own experiment, from a few answers: a ball in flight, a ball on a surface, a
pendulum or a puck (``physbench scene new``).

:func:`build_setup` makes the :class:`~physbench.scene.Scene` of one :data:`SETUPS` kind from
:class:`Answers`; what is not answered is estimated from a recording's first samples
(:func:`estimate`) when one is given:

- ``flight``: a ball thrown or dropped, seen from the side (gravity ``-9.81`` m/s² along ``y``).
  Its position and velocity at the first sample come from a least-squares quadratic in time of
  each coordinate over the first :data:`FIRST_SECONDS` of samples (the acceleration is fitted,
  not assumed: drag slows a throw within that time).
- ``surface``: a ball rolling or sliding along a straight surface (level, or a ramp at
  ``surface_angle`` degrees), seen from the side. The surface is a static segment one radius
  under the ball's centre; the velocity is along it (a quadratic fit of the distance along it).
- ``pendulum``: a bob on a rod or string from a ``pivot`` (a pivot joint: the bob swings as a
  rigid body about it). Without a pivot, the least-squares circle through the samples gives it;
  a cubic fit of the angle gives the initial angular velocity.
- ``puck``: a disc sliding on a table seen from above (no gravity in the plane); fitted as a
  flight is.

The frame rate and the number of frames come from the answers, else the recording (its median
sample interval and its length); the bounds hold the recorded path (or the given image
footprint) with a margin. The mass is a made-up 1 kg unless given: a free body's motion does not
depend on it, and an effect's force then comes out per kilogram.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from physbench.errors import PhysbenchError
from physbench.recording import Recording, Track
from physbench.scene import Body, Circle, Joint, Scene, Segment

SETUPS = ("flight", "surface", "pendulum", "puck")
#: Default body name of each setup.
BODY_NAMES = {"flight": "ball", "surface": "ball", "pendulum": "bob", "puck": "puck"}
G = 9.81
#: Seconds of samples the initial state is fitted to.
FIRST_SECONDS = 0.3
#: Fewest samples an estimate uses (more if the first seconds hold more).
FIRST_SAMPLES = 4
#: A fit's scatter over this many times the recording's accuracy is not free motion.
SCATTER = 4.0
#: An acceleration past gravity's along the motion over this share of g is not free motion.
PUSH = 0.05
#: Physics steps per second at least (substeps = this / fps, rounded up, at least 4).
STEPS_PER_SECOND = 600.0


class SetupError(PhysbenchError, ValueError):
    """A setup that cannot be built: names the missing or bad answer."""


@dataclass(frozen=True)
class Answers:
    """What the person tells: every field but ``kind`` and ``radius`` may be left ``None`` when
    a recording is given to estimate it."""

    kind: str
    radius: float
    body: str | None = None
    mass: float | None = None
    fps: float | None = None
    frames: int | None = None
    position: tuple[float, float] | None = None
    velocity: tuple[float, float] | None = None
    pivot: tuple[float, float] | None = None
    surface_angle: float = 0.0  # degrees, counter-clockwise from +x
    bounds: tuple[float, float, float, float] | None = None
    name: str | None = None


@dataclass(frozen=True)
class Estimate:
    """Initial state fitted to a recording's first samples, and what it was fitted on."""

    position: tuple[float, float]
    velocity: tuple[float, float]
    pivot: tuple[float, float] | None
    samples: int
    rms: float  # m, the fit's residual over those samples
    #: A flight's or puck's fitted acceleration (m/s²) over those samples, and its standard error.
    acceleration: tuple[float, float] | None = None
    acceleration_se: float = 0.0


def _first(track: Track, seconds: float = FIRST_SECONDS) -> np.ndarray:
    """Indices of the first samples: those within ``seconds`` of the first, at least
    :data:`FIRST_SAMPLES`."""
    n = max(FIRST_SAMPLES, int(np.searchsorted(track.t, track.t[0] + seconds, side="right")))
    if len(track) < FIRST_SAMPLES:
        raise SetupError(
            f"the recording has {len(track)} samples of this body; estimating its initial state "
            f"needs at least {FIRST_SAMPLES}: give --position and --velocity instead"
        )
    return np.arange(min(n, len(track)))


def _fit(t: np.ndarray, y: np.ndarray, degree: int) -> tuple[np.ndarray, float]:
    """Polynomial coefficients (constant first) and RMS residual."""
    c, rms, _ = _fit_se(t, y, degree)
    return c, rms


def _fit_se(t: np.ndarray, y: np.ndarray, degree: int) -> tuple[np.ndarray, float, np.ndarray]:
    """:func:`_fit`, and the coefficients' standard errors (from the residual; 0 where the
    samples leave no degree of freedom)."""
    a = np.vander(t, degree + 1, increasing=True)
    c, *_ = np.linalg.lstsq(a, y, rcond=None)
    rss = float(np.sum((a @ c - y) ** 2))
    free = len(t) - degree - 1
    cov = np.linalg.pinv(a.T @ a) * (rss / free if free > 0 else 0.0)
    return c, math.sqrt(rss / len(t)), np.sqrt(np.maximum(np.diag(cov), 0.0))


def fit_circle(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Centre and radius of the least-squares circle through points (the algebraic fit
    ``x² + y² + D x + E y + F = 0``)."""
    a = np.column_stack([x, y, np.ones_like(x)])
    b = -(x * x + y * y)
    (d, e, f), *_ = np.linalg.lstsq(a, b, rcond=None)
    cx, cy = -d / 2, -e / 2
    r2 = cx * cx + cy * cy - f
    if not r2 > 0:
        raise SetupError("the samples do not lie on a circle: give --pivot")
    return float(cx), float(cy), math.sqrt(r2)


def estimate(
    kind: str, track: Track, *, pivot: Sequence[float] | None = None, angle: float = 0.0
) -> Estimate:
    """The initial state (at the track's first sample) of a ``kind`` setup, fitted to the
    track's first samples (see the module docstring); ``angle``: a surface's, in degrees."""
    idx = _first(track)
    t = track.t[idx] - track.t[0]
    x, y = track.x[idx], track.y[idx]
    if kind in ("flight", "puck"):
        # Quadratic in both: the drag or friction being looked for slows the body within 0.3 s,
        # and a fit without it would give the window's mean velocity, not the first sample's.
        cx, rx, ex = _fit_se(t, x, 2)
        cy, ry, ey = _fit_se(t, y, 2)
        acc = (2 * float(cx[2]), 2 * float(cy[2]))
        se = 2 * math.hypot(ex[2], ey[2])
        return Estimate((cx[0], cy[0]), (cx[1], cy[1]), None, len(idx), math.hypot(rx, ry), acc, se)
    if kind == "surface":
        a = math.radians(angle)
        along = x * math.cos(a) + y * math.sin(a)
        across = -x * math.sin(a) + y * math.cos(a)
        c, r = _fit(t, along, 2)
        off = float(np.mean(across))
        pos = (c[0] * math.cos(a) - off * math.sin(a), c[0] * math.sin(a) + off * math.cos(a))
        rms = math.hypot(r, float(np.std(across)))
        return Estimate(pos, (c[1] * math.cos(a), c[1] * math.sin(a)), None, len(idx), rms)
    if kind == "pendulum":
        if pivot is None:
            px, py, _ = fit_circle(track.x, track.y)
        else:
            px, py = float(pivot[0]), float(pivot[1])
        theta = np.unwrap(np.arctan2(x - px, -(y - py)))
        c, _ = _fit(t, theta, 3)  # a swing's angular acceleration changes within 0.3 s
        length = float(np.mean(np.hypot(x - px, y - py)))
        th, om = float(c[0]), float(c[1])
        pos = (px + length * math.sin(th), py - length * math.cos(th))
        vel = (length * om * math.cos(th), length * om * math.sin(th))
        fitted = np.column_stack([px + length * np.sin(theta), py - length * np.cos(theta)])
        rms = float(np.sqrt(np.mean(np.sum((fitted - np.column_stack([x, y])) ** 2, axis=1))))
        return Estimate(pos, vel, (px, py), len(idx), rms)
    raise SetupError(f"kind {kind!r}: expected one of {', '.join(SETUPS)}")


def start_from_points(kind: str, points: Sequence[Sequence[float]], fps: float) -> Estimate:
    """Position and velocity at the first of ``points`` (m), the body's centre in consecutive
    frames at ``fps`` (e.g. read off the first frames of a clip): a straight-line fit, with
    gravity taken out for a flight."""
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 1:
        raise SetupError(f"points {points!r}: expected [x, y] pairs")
    if len(p) == 1:
        return Estimate((float(p[0, 0]), float(p[0, 1])), (0.0, 0.0), None, 1, 0.0)
    t = np.arange(len(p)) / fps
    a = G if kind == "flight" else 0.0
    cx, rx = _fit(t, p[:, 0], 1)
    cy, ry = _fit(t, p[:, 1] + 0.5 * a * t * t, 1)
    return Estimate((cx[0], cy[0]), (cx[1], cy[1]), None, len(p), math.hypot(rx, ry))


def _clock(answers: Answers, rec: Recording | None) -> tuple[float, int]:
    fps, frames = answers.fps, answers.frames
    if fps is None and rec is not None:
        steps = np.concatenate([np.diff(tr.t) for tr in rec.tracks.values()])
        steps = steps[steps > 0]
        if steps.size:
            # Times are sums of float steps: 80.00000000000028 is 80 frames/s.
            fps = float(f"{1.0 / float(np.median(steps)):.9g}")
    if fps is None or not (math.isfinite(fps) and fps > 0):
        raise SetupError("the frame rate is unknown: give --fps, --video or a recording")
    if frames is None and rec is not None:
        frames = rec.frames_for(fps)
    if frames is None or frames < 2:
        raise SetupError(
            f"frames = {frames!r}: give --frames (or --video or a recording) for at least 2"
        )
    return float(fps), int(frames)


def _bounds(answers: Answers, points: np.ndarray, radius: float) -> tuple[float, ...]:
    if answers.bounds is not None:
        return tuple(float(v) for v in answers.bounds)
    lo, hi = points.min(axis=0) - radius, points.max(axis=0) + radius
    pad = max(0.15 * float((hi - lo).max()), 4 * radius, 0.1)
    return (float(lo[0] - pad), float(lo[1] - pad), float(hi[0] + pad), float(hi[1] + pad))


def build_setup(answers: Answers, recording: Recording | None = None) -> tuple[Scene, list[str]]:
    """The scene of ``answers`` (see the module docstring), and a line per estimated value
    saying where it came from."""
    kind = answers.kind
    if kind not in SETUPS:
        raise SetupError(f"kind {kind!r}: expected one of {', '.join(SETUPS)}")
    if not (isinstance(answers.radius, int | float) and answers.radius > 0):
        raise SetupError(f"radius = {answers.radius!r}: expected metres > 0")
    r = float(answers.radius)
    name = answers.body or _track_name(recording) or BODY_NAMES[kind]
    notes: list[str] = []
    fps, frames = _clock(answers, recording)
    pos, vel, pivot = answers.position, answers.velocity, answers.pivot
    path = np.zeros((0, 2))
    if recording is not None:
        track = recording.track(name)
        path = np.column_stack([track.x, track.y])
        if pos is None or vel is None or (kind == "pendulum" and pivot is None):
            est = estimate(kind, track, pivot=pivot, angle=answers.surface_angle)
            what = []
            if pos is None:
                pos, what = est.position, [*what, "position"]
            if vel is None:
                vel, what = est.velocity, [*what, "velocity"]
            if pivot is None and est.pivot is not None:
                pivot, what = est.pivot, [*what, "pivot (circle through all samples)"]
            notes.append(
                f"{', '.join(what)} of {name!r} fitted to its first {est.samples} samples "
                f"(residual {est.rms * 1000:.1f} mm RMS); recording time 0 is simulation time 0"
            )
            _say_if_not_free(kind, name, est, recording.accuracy)
    if pos is None:
        raise SetupError("the initial position is unknown: give --position (or --pixel) or --from")
    vel = (0.0, 0.0) if vel is None else vel
    if vel == (0.0, 0.0) and recording is None and answers.velocity is None:
        notes.append("velocity not given: 0 (the body starts at rest)")
    if answers.mass is None:
        notes.append("mass not given: 1 kg (free motion does not depend on it)")
    mass = 1.0 if answers.mass is None else float(answers.mass)
    extent = np.vstack([path, [pos]]) if len(path) else np.array([pos], dtype=float)
    body = Body(name, Circle(r), _vec(pos), velocity=_vec(vel), mass=mass)
    gravity = (0.0, 0.0) if kind == "puck" else (0.0, -G)
    statics: tuple = ()
    joints: tuple = ()
    if kind == "surface":
        statics = (_surface(pos, r, answers.surface_angle, extent),)
        body = Body(name, Circle(r), _vec(pos), velocity=_vec(vel), mass=mass, elasticity=0.0)
    if kind == "pendulum":
        if pivot is None:
            raise SetupError("the pivot is unknown: give --pivot X Y (or a recording to fit it)")
        px, py = float(pivot[0]), float(pivot[1])
        arm = (pos[0] - px, pos[1] - py)
        if math.hypot(*arm) <= r:
            raise SetupError(f"pivot {pivot} lies inside the bob: give the pivot of the string")
        omega = (arm[0] * vel[1] - arm[1] * vel[0]) / (arm[0] ** 2 + arm[1] ** 2)
        body = Body(
            name, Circle(r), _vec(pos), velocity=_vec(vel), angular_velocity=omega, mass=mass
        )
        joints = (Joint(name, (px, py)),)
        extent = np.vstack([extent, [[px, py]]])
    bounds = _bounds(answers, extent, r)
    scene = Scene(
        answers.name or f"my_{kind}",
        (body,),
        bounds=bounds,  # type: ignore[arg-type]
        gravity=gravity,
        fps=fps,
        frames=frames,
        substeps=max(4, math.ceil(STEPS_PER_SECOND / fps)),
        statics=statics,
        joints=joints,
        description=f"{kind} setup made by physbench scene new",
    )
    return scene.validate(), notes


def _say_if_not_free(kind: str, name: str, est: Estimate, accuracy: float) -> None:
    """Warn where a flight's or puck's first samples are not free motion, from which its start
    was fitted: they scatter about the fit by over :data:`SCATTER` times the recording's
    ``accuracy`` (m), or they speed up beyond gravity (drag and friction only slow a free
    body: an acceleration past gravity's along the velocity, by over 3 standard errors and
    :data:`PUSH` g, is a hand or a string still acting)."""
    import warnings

    from physbench.errors import PhysbenchWarning

    if kind not in ("flight", "puck") or est.acceleration is None:
        return
    said = []
    if accuracy > 0 and est.rms > SCATTER * accuracy:
        said.append(
            f"they scatter {est.rms * 1000:.1f} mm RMS about the fit, {est.rms / accuracy:.0f} "
            f"times the recording's accuracy ({accuracy * 1000:.1f} mm)"
        )
    free = np.array([0.0, 0.0 if kind == "puck" else -G])
    extra = np.asarray(est.acceleration) - free
    speed = math.hypot(*est.velocity)
    push = float(extra @ est.velocity) / speed if speed > 0 else 0.0
    if push > 3 * est.acceleration_se + PUSH * G:
        ax, ay = est.acceleration
        said.append(
            f"they accelerate at ({ax:.2f}, {ay:.2f}) m/s², {push:.2f} m/s² along the motion "
            f"beyond {'gravity' if kind == 'flight' else 'none'} (drag and friction only slow "
            "a free body)"
        )
    if said:
        warnings.warn(
            f"the first {est.samples} samples of {name!r}, which its start is fitted to, are not "
            f"a free {kind}: {'; '.join(said)}. Is it still held or pulled there? Start the "
            "recording after the release (in Tracker: mark from the release on), or give "
            "--position and --velocity",
            PhysbenchWarning,
            stacklevel=3,
        )


def _vec(v: Sequence[float]) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def _surface(pos: Sequence[float], r: float, angle: float, path: np.ndarray) -> Segment:
    """The surface one radius under the ball's centre, along ``angle``, spanning the path."""
    a = math.radians(angle)
    d = np.array([math.cos(a), math.sin(a)])
    normal = np.array([-d[1], d[0]])
    foot = np.asarray(pos, dtype=float) - r * normal
    along = (path - foot) @ d
    span = max(float(along.max() - along.min()), 10 * r)
    lo, hi = float(along.min()) - 0.25 * span, float(along.max()) + 0.25 * span
    a_pt, b_pt = foot + lo * d, foot + hi * d
    return Segment((float(a_pt[0]), float(a_pt[1])), (float(b_pt[0]), float(b_pt[1])), friction=0.5)


def _track_name(recording: Recording | None) -> str | None:
    if recording is None:
        return None
    if len(recording.bodies) != 1:
        raise SetupError(
            f"the recording tracks {len(recording.bodies)} bodies "
            f"({', '.join(recording.bodies)}): name one with --body"
        )
    return recording.bodies[0]


def format_setup(scene: Scene, notes: Sequence[str] = ()) -> str:
    """The scene as a short TOML file with the notes as comments (:func:`loads_scene` reads it
    back to the same scene)."""
    (b,) = scene.bodies

    def v(p: Sequence[float]) -> str:
        return "[" + ", ".join(repr(float(c)) for c in p) + "]"

    def q(text: str) -> str:
        return json.dumps(text, ensure_ascii=False)  # a TOML basic string

    lines = [f"# {n}" for n in notes]
    lines += [
        f"name = {q(scene.name)}",
        f"description = {q(scene.description)}",
        f"bounds = {v(scene.bounds)}",
        f"gravity = {v(scene.gravity)}",
        f"fps = {float(scene.fps)!r}",
        f"frames = {scene.frames}",
        f"substeps = {scene.substeps}",
        "",
        "[[bodies]]",
        f"name = {q(b.name)}",
        f'shape = {{ kind = "circle", radius = {float(b.shape.radius)!r} }}',  # type: ignore[union-attr]
        f"position = {v(b.position)}",
        f"velocity = {v(b.velocity)}",
    ]
    if b.angular_velocity:
        lines.append(f"angular_velocity = {float(b.angular_velocity)!r}")
    lines += [f"mass = {float(b.mass)!r}", f"elasticity = {float(b.elasticity)!r}"]
    for st in scene.statics:
        assert isinstance(st, Segment)
        lines += ["", "[[statics]]", 'kind = "segment"', f"a = {v(st.a)}", f"b = {v(st.b)}"]
        lines.append(f"friction = {float(st.friction)!r}")
    for j in scene.joints:
        lines += ["", "[[joints]]", f"a = {q(j.a)}", f"anchor = {v(j.anchor)}"]
    return "\n".join(lines) + "\n"
