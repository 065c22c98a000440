"""Residuals, laid out: which body, field and time each entry of a residual vector belongs to, the
event each sample falls in (free flight, impact, contact, jointed), and per body / per event
summaries of a residual vector.

A recording's residual vector (:meth:`~physbench.recording.Recording.residuals`) is ordered by body,
then field, then time; :class:`Layout` mirrors that order. When a recording mixes positions and
angles, angle residuals are weighted by the body's size (m per rad) so that both are in metres.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from physbench.recording import POSE_FIELDS, Recording
from physbench.scene import Scene, Segment
from physbench.trajectory import Trajectory

EVENTS = ("free", "impact", "contact", "jointed")


def recording_fields(rec: Recording) -> tuple[str, ...]:
    """The fields :meth:`Recording.residuals` compares by default."""
    fields = rec.fields if rec.fields is not None else POSE_FIELDS
    return tuple(f for f in fields if any(f in tr.fields for tr in rec.tracks.values()))


@dataclass(frozen=True, eq=False)
class Layout:
    """Per residual entry: body name index, field index (0 x, 1 y, 2 angle, -1 pixel), time,
    weight."""

    bodies: tuple[str, ...]
    body: np.ndarray
    field: np.ndarray
    t: np.ndarray
    weight: np.ndarray
    unit: str

    @property
    def size(self) -> int:
        return int(self.t.size)

    @classmethod
    def of_recording(cls, rec: Recording, scene: Scene) -> Layout:
        fields = recording_fields(rec)
        mixed = "angle" in fields and len(fields) > 1
        body, field, t, w = [], [], [], []
        names = rec.bodies
        for i, name in enumerate(names):
            tr = rec.track(name)
            size = scene.bodies[scene.body_index(name)].shape.extent()
            for f in fields:
                if f not in tr.fields:
                    continue
                n = len(tr)
                body.append(np.full(n, i))
                field.append(np.full(n, POSE_FIELDS.index(f)))
                t.append(tr.t)
                w.append(np.full(n, size if (mixed and f == "angle") else 1.0))
        unit = "rad" if fields == ("angle",) else ("m (angles × body size)" if mixed else "m")
        return cls(
            names,
            np.concatenate(body),
            np.concatenate(field),
            np.concatenate(t),
            np.concatenate(w),
            unit,
        )

    @classmethod
    def of_frames(cls, frame_index: np.ndarray, shape: tuple[int, ...], fps: float) -> Layout:
        per = int(np.prod(shape[1:]))
        t = np.repeat(np.asarray(frame_index, dtype=float) / fps, per)
        n = t.size
        return cls(
            ("image",), np.zeros(n, dtype=int), np.full(n, -1), t, np.ones(n), "pixel intensity"
        )


def rms(r: np.ndarray) -> float:
    return float(np.sqrt(np.mean(r * r))) if r.size else math.nan


# --------------------------------------------------------------------------- events


def _segment_distance(p: np.ndarray, a: tuple[float, float], b: tuple[float, float]) -> np.ndarray:
    a_, b_ = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    d = b_ - a_
    s = np.clip(((p - a_) @ d) / float(d @ d), 0.0, 1.0)
    return np.hypot(*(p - (a_ + s[..., None] * d)).T)


def _static_distance(scene: Scene, p: np.ndarray) -> np.ndarray:
    """Distance (m) from points ``(T, 2)`` to the nearest static surface (inf without statics)."""
    best = np.full(p.shape[0], np.inf)
    for s in scene.statics:
        if isinstance(s, Segment):
            best = np.minimum(best, _segment_distance(p, s.a, s.b) - s.radius)
        else:
            pts = s.points
            d = np.min(
                [_segment_distance(p, pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))],
                axis=0,
            )
            best = np.minimum(best, d)
    return best


def frame_events(scene: Scene, traj: Trajectory, *, margin: float = 0.01) -> np.ndarray:
    """``(T, N)`` event index (into :data:`EVENTS`) of every simulated frame and body.

    ``impact``: the velocity of a body that is not jointed jumps between two frames by more than
    gravity and 5 % of the speed (plus 5 cm/s) explain, on both frames around the jump;
    ``contact``: within ``margin`` (m) plus the body's size of static geometry or another body;
    ``jointed``: on a pivot joint; else ``free``.
    """
    s = traj.states
    T, n = s.shape[0], s.shape[1]
    out = np.zeros((T, n), dtype=int)
    dt = float(traj.times[1] - traj.times[0]) if T > 1 else 1.0
    g = np.asarray(scene.gravity, dtype=float)
    jointed = {j.a for j in scene.joints} | {j.b for j in scene.joints if j.b is not None}
    ext = np.array([b.shape.extent() for b in scene.bodies])
    for i, b in enumerate(scene.bodies):
        if b.name in jointed:
            out[:, i] = EVENTS.index("jointed")
        pos = s[:, i, :2]
        near = _static_distance(scene, pos) < ext[i] + margin
        for k in range(n):
            if k != i:
                near |= np.hypot(*(pos - s[:, k, :2]).T) < ext[i] + ext[k] + margin
        out[near, i] = EVENTS.index("contact")
        if T > 1 and b.name not in jointed:  # a joint's constraint force is no impact
            v = s[:, i, 3:5]
            jump = np.hypot(*(np.diff(v, axis=0) - g * dt).T)
            speed = np.hypot(*v.T)
            hit = jump > 0.05 + 0.05 * np.maximum(speed[:-1], speed[1:])
            idx = np.nonzero(hit)[0]
            for k in (0, 1):
                out[np.clip(idx + k, 0, T - 1), i] = EVENTS.index("impact")
    return out


def sample_events(layout: Layout, events: np.ndarray, fps: float) -> np.ndarray:
    """Event index of every residual entry (``events`` from :func:`frame_events`)."""
    k = np.clip(np.rint(layout.t * fps).astype(int), 0, events.shape[0] - 1)
    return events[k, layout.body] if layout.field[0] >= 0 else np.zeros(layout.size, dtype=int)


@dataclass(frozen=True)
class Breakdown:
    """RMS residual per body and field, and per body and event (``None`` where no samples)."""

    per_field: dict[str, dict[str, float]]
    per_event: dict[str, dict[str, float]]
    counts: dict[str, dict[str, int]]

    def to_dict(self) -> dict[str, object]:
        return {
            "per_field": self.per_field,
            "per_event": self.per_event,
            "samples_per_event": self.counts,
        }


def breakdown(
    parts: Sequence[tuple[Layout, np.ndarray, np.ndarray | None, Sequence[str]]],
) -> Breakdown:
    """Summaries over several (layout, residuals, sample events, body-name map) parts, pooled by
    body name."""
    sq_f: dict[str, dict[str, list[float]]] = {}
    sq_e: dict[str, dict[str, list[float]]] = {}
    for layout, r, ev, names in parts:
        for b in range(len(names)):
            sel = layout.body == b
            if not sel.any():
                continue
            name = names[b]
            for f in np.unique(layout.field[sel]):
                m = sel & (layout.field == f)
                key = POSE_FIELDS[f] if f >= 0 else "pixels"
                sq_f.setdefault(name, {}).setdefault(key, []).extend((r[m] ** 2).tolist())
            if ev is not None:
                for e in np.unique(ev[sel]):
                    m = sel & (ev == e)
                    sq_e.setdefault(name, {}).setdefault(EVENTS[e], []).extend((r[m] ** 2).tolist())
    per_field = {b: {f: float(np.sqrt(np.mean(v))) for f, v in d.items()} for b, d in sq_f.items()}
    per_event = {b: {e: float(np.sqrt(np.mean(v))) for e, v in d.items()} for b, d in sq_e.items()}
    counts = {b: {e: len(v) for e, v in d.items()} for b, d in sq_e.items()}
    return Breakdown(per_field, per_event, counts)
