"""A real three-cushion billiards match (Dogan, 2022-12-25): 182 shots, tracked ball centres.

Each shot becomes a :class:`~physbench.datasets.recorded_run.DatasetRun`: a top-down scene (gravity
0) of the 2.84 × 1.42 m table, its four cushions as thick segments whose inner surface is the table
edge, and the three balls (``white``, ``yellow``, ``red``) at rest at their first tracked
positions. The cue strike is an impulse on the cue ball (see :func:`cue_strike`); tracking starts
slightly before it. The recording has ``x, y``; balls are only sampled while they move.

The plain model misses rolling resistance, cushion losses and spin (see PROVENANCE.md);
:func:`rolling_decelerations` measures the first from the tracks. :func:`rolling_segments` cuts
each ball's track after its last contact with another ball, where only rolling and the cushions
act; :func:`cushion_bounces` and :func:`straight_stretches` measure those two on such a segment.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from physbench.datasets.files import DatasetError, data_dir, data_file
from physbench.datasets.recorded_run import DatasetRun
from physbench.recording import Recording, Track
from physbench.scene import Body, Circle, Force, Scene, Segment, body_unknown

NAME = "billiards"
FOLDER = "billiards_dogan"
TABLE = (2.84, 1.42)  # m, playing surface
BALL_RADIUS = 0.03075  # m
#: Carom balls weigh 205-220 g; the data do not say.
BALL_MASS = 0.21
BALLS = {1: "white", 2: "yellow", 3: "red"}
CUSHION_THICKNESS = 0.05  # m; thick so that fast balls cannot tunnel through
#: A time step longer than this means the ball was at rest during it (sampling is event-like).
MAX_START_STEP = 0.1  # s


@functools.lru_cache(maxsize=2)
def _table(path: Path) -> np.ndarray:
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[1] != 6:
        raise DatasetError(
            f"{path}: expected 6 columns shot_index,shot_id,ball_id,t_s,x_m,y_m, "
            f"got {data.shape[1]}"
        )
    return data


def read_table(root: str | Path | None = None) -> np.ndarray:
    """All rows ``(shot_index, shot_id, ball_id, t_s, x_m, y_m)``, from the CSV or its .gz copy."""
    folder = data_dir(FOLDER, root)
    return _table(data_file(folder, "shots_20221225_2_match.csv", "shots_20221225_2_match.csv.gz"))


def cushions(elasticity: float = 0.9, friction: float = 0.0) -> tuple[Segment, ...]:
    """Four thick segments whose inner surfaces are the table edges x = 0, x = W, y = 0, y = H."""
    w, h = TABLE
    r = CUSHION_THICKNESS
    lo, hx, hy = -r - r, w + r + r, h + r + r  # long enough to close the corners
    return tuple(
        Segment(a, b, radius=r, elasticity=elasticity, friction=friction)
        for a, b in (
            ((lo, -r), (hx, -r)),
            ((lo, h + r), (hx, h + r)),
            ((-r, lo), (-r, hy)),
            ((w + r, lo), (w + r, hy)),
        )
    )


def cue_strike(track: Track) -> tuple[float, tuple[float, float]] | None:
    """When the cue ball was struck and its velocity just after: the velocity of the first short
    step after its first move (the step that contains the strike is slower, as the ball rested
    during part of it), and the time at which moving at that velocity from the rest position
    reaches the first moved sample. ``None`` when the ball never moves in short steps."""
    t, x, y = track.t, track.x, track.y
    moving = np.nonzero(np.diff(t) <= MAX_START_STEP)[0]
    if moving.size == 0:
        return None
    k = int(moving[0])  # step k -> k+1 contains the strike
    j = k + 1 if k + 2 < t.size and t[k + 2] - t[k + 1] <= MAX_START_STEP else k
    dt = float(t[j + 1] - t[j])
    v = (float(x[j + 1] - x[j]) / dt, float(y[j + 1] - y[j]) / dt)
    speed = float(np.hypot(*v))
    if speed == 0.0:
        return None
    moved = float(np.hypot(x[k + 1] - x[k], y[k + 1] - y[k]))
    t_s = float(np.clip(t[k + 1] - moved / speed, t[k], t[k + 1]))
    return t_s, v


def load(
    shots: Iterable[int] | None = None,
    *,
    root: str | Path | None = None,
    fps: float = 50.0,
    substeps: int = 10,
    ball_elasticity: float = 0.95,
    cushion_elasticity: float = 0.9,
) -> list[DatasetRun]:
    """One run per shot (``shots``: shot indices 0-181, default all)."""
    data = read_table(root)
    index = data[:, 0].astype(int)
    available = np.unique(index)
    chosen = available if shots is None else np.asarray(list(shots), dtype=int)
    cases = []
    for shot in chosen:
        if shot not in available:
            raise DatasetError(f"no shot {shot}; shots are {available[0]}..{available[-1]}")
        rows = data[index == shot]
        tracks: dict[str, Track] = {}
        for bid, name in BALLS.items():
            r = rows[rows[:, 2] == bid]
            if r.shape[0] == 0:
                raise DatasetError(f"shot {shot} has no samples of ball {bid} ({name})")
            r = r[np.argsort(r[:, 3], kind="stable")]
            tracks[name] = Track(r[:, 3], r[:, 4], r[:, 5])
        counts = {name: len(tr) for name, tr in tracks.items()}
        cue = "white" if counts["white"] >= counts["yellow"] else "yellow"
        strike = cue_strike(tracks[cue])
        bodies = tuple(
            Body(
                name,
                Circle(BALL_RADIUS),
                (float(tr.x[0]), float(tr.y[0])),
                mass=BALL_MASS,
                elasticity=ball_elasticity,
                friction=0.0,
            )
            for name, tr in tracks.items()
        )
        forces = ()
        if strike is not None:
            t_s, (vx, vy) = strike
            forces = (Force(cue, (BALL_MASS * vx, BALL_MASS * vy), start=t_s, kind="impulse"),)
        shot_id = int(rows[0, 1])
        rec = Recording(
            tracks,
            run=str(shot),
            fields=("x", "y"),
            source=FOLDER,
            meta={"shot_id": shot_id, "cue": cue},
        )
        margin = 0.1
        scene = Scene(
            name=f"billiards_shot_{shot}",
            bodies=bodies,
            bounds=(-margin, -margin, TABLE[0] + margin, TABLE[1] + margin),
            gravity=(0.0, 0.0),
            fps=fps,
            frames=rec.frames_for(fps),
            substeps=substeps,
            statics=cushions(cushion_elasticity),
            forces=forces,
            description=(
                f"three-cushion shot {shot} (tracking id {shot_id}), cue ball {cue}, top-down"
            ),
            meta={"dataset": NAME, "cue": cue},
        ).validate()
        notes = {
            "shot_id": shot_id,
            "cue": cue,
            "strike": None
            if strike is None
            else {"t_s": strike[0], "speed_mps": float(np.hypot(*strike[1]))},
            "ball_mass_assumed": True,
            "samples": counts,
        }
        cases.append(
            DatasetRun(
                f"shot_{shot}",
                scene,
                rec,
                ("rolling_resistance", "velocity_dependent_restitution"),
                notes,
            )
        )
    return cases


def rolling_decelerations(
    recording: Recording,
    *,
    min_duration: float = 1.0,
    speed_range: tuple[float, float] = (0.05, 0.6),
    max_turn_deg: float = 4.0,
    max_gap: float = 0.5,
) -> np.ndarray:
    """Deceleration (m/s², positive when slowing) of each straight, cushion-free stretch of a
    ball's track at least ``min_duration`` long, with speeds in ``speed_range``: a least-squares
    fit of ``s(t) = s0 + v0 t - a t²/2`` to the distance travelled. Stretches end where the heading
    turns by more than ``max_turn_deg`` between samples, where the ball touches the cushion line
    (positions are clipped there), and at gaps over ``max_gap`` s."""
    w, h = TABLE
    edge = BALL_RADIUS + 2e-3
    out = []
    for tr in recording.tracks.values():
        t, x, y = tr.t, tr.x, tr.y
        if t.size < 10:
            continue
        cushion = (x < edge) | (x > w - edge) | (y < edge) | (y > h - edge)
        dx, dy, dt = np.diff(x), np.diff(y), np.diff(t)
        heading = np.arctan2(dy, dx)
        turn = np.zeros(dt.size, dtype=bool)
        turn[1:] = np.abs(np.angle(np.exp(1j * np.diff(heading)))) > np.radians(max_turn_deg)
        ok = ~(cushion[:-1] | cushion[1:]) & (dt <= max_gap)
        i = 0
        while i < dt.size:
            if not ok[i]:
                i += 1
                continue
            j = i + 1
            while j < dt.size and ok[j] and not turn[j]:
                j += 1
            tt = t[i : j + 1] - t[i]
            if tt[-1] >= min_duration and j - i >= 10:
                s = np.concatenate([[0.0], np.cumsum(np.hypot(dx[i:j], dy[i:j]))])
                a = np.stack([np.ones_like(tt), tt, -0.5 * tt**2], axis=1)
                (_, v0, dec), *_ = np.linalg.lstsq(a, s, rcond=None)
                v_end = v0 - dec * tt[-1]
                if speed_range[0] <= v_end and v0 <= speed_range[1]:
                    out.append(dec)
            i = j
    return np.asarray(out)


# --------------------------------------------------------------------------- rolling segments

#: Time after a ball's last contact with another ball before its rolling segment starts: after a
#: hit a ball slides (friction about 10x rolling resistance) until it rolls, which a 2D scene lacks.
SEGMENT_SETTLE = 1.0  # s
#: Shortest rolling segment.
MIN_SEGMENT = 3.0  # s
#: Fewest samples of a ball's whole track, and of its segment.
MIN_TRACK_SAMPLES, MIN_SEGMENT_SAMPLES = 60, 40
#: Slowest start of a segment (from a line through its first 6 samples).
MIN_SEGMENT_SPEED = 0.3  # m/s
#: Samples are 2-4 cm apart at speed: a contact can fall between two of them, so two balls count
#: as touching up to this far beyond touching.
CONTACT_MARGIN = 0.04  # m


def last_ball_contact(recording: Recording, ball: str) -> float:
    """When ``ball`` last touched another ball (0 when never): the last sample at which another
    ball is within :data:`CONTACT_MARGIN` of touching it, or the time another ball starts to
    move (something hit it), whichever is later."""
    tr = recording.tracks[ball]
    t_last = 0.0
    for other, o in recording.tracks.items():
        if other == ball:
            continue
        ox, oy = np.interp(tr.t, o.t, o.x), np.interp(tr.t, o.t, o.y)
        close = np.hypot(tr.x - ox, tr.y - oy) < 2 * BALL_RADIUS + CONTACT_MARGIN
        if close.any():
            t_last = max(t_last, float(tr.t[np.nonzero(close)[0][-1]]))
        if len(o) > 2:
            started = (
                float(o.t[0])
                if o.t[0] > 0.05
                else float(o.t[np.argmax(np.diff(o.t) <= MAX_START_STEP)])
            )
            t_last = max(t_last, started)
    return t_last


def rolling_segment(
    shot: DatasetRun, ball: str, max_speed: float | None = None
) -> DatasetRun | None:
    """``ball``'s track in ``shot`` from :data:`SEGMENT_SETTLE` after its last contact with
    another ball (:func:`last_ball_contact`) to the end of the shot, when at least
    :data:`MIN_SEGMENT` long and moving at its start: a run of one ball ``ball`` on the table that
    only rolling and the cushions act on, its time from 0 at the segment's start. With
    ``max_speed`` (m/s), the segment starts when the ball is first slower than that. ``None`` when
    the track holds no such segment.

    The ball is frictionless and unpushed, its start velocity a line through the segment's first
    6 samples. The scene's one unknown is the ball's elasticity against cushions of elasticity 1,
    with one body name for every segment, so that runs of different balls and shots share the
    cushion restitution. Its range, 0.4-1, brackets the 0.55-0.6 that :func:`cushion_bounces`
    measures; a lossless base fit would otherwise make up for the missing rolling loss at the
    cushions."""
    rec = shot.recording
    tr = rec.tracks[ball]
    if len(tr) < MIN_TRACK_SAMPLES:
        return None
    t0 = last_ball_contact(rec, ball) + SEGMENT_SETTLE
    if max_speed is not None:
        dt = np.diff(tr.t)
        sp = np.hypot(np.diff(tr.x), np.diff(tr.y)) / dt
        slow = np.nonzero((tr.t[1:] >= t0) & (sp < max_speed) & (dt <= MAX_START_STEP))[0]
        if slow.size == 0:
            return None
        t0 = float(tr.t[slow[0]])
    keep = tr.t >= t0
    if keep.sum() < MIN_SEGMENT_SAMPLES or tr.t[-1] - t0 < MIN_SEGMENT:
        return None
    t, x, y = tr.t[keep] - tr.t[keep][0], tr.x[keep], tr.y[keep]
    if np.any(np.diff(t[:6]) > MAX_START_STEP):  # must start while moving
        return None
    vx, vy = np.polyfit(t[:6], x[:6], 1)[0], np.polyfit(t[:6], y[:6], 1)[0]
    if math.hypot(vx, vy) < MIN_SEGMENT_SPEED:
        return None
    name = f"{shot.name}/{ball}"
    recording = Recording({"ball": Track(t, x, y)}, run=name, fields=("x", "y"), source=rec.source)
    scene = replace(
        shot.scene,
        name=f"billiards_{shot.name}_{ball}",
        bodies=(
            Body(
                "ball",
                Circle(BALL_RADIUS),
                (float(x[0]), float(y[0])),
                velocity=(float(vx), float(vy)),
                mass=BALL_MASS,
                elasticity=0.85,
                friction=0.0,
            ),
        ),
        statics=cushions(1.0),
        forces=(),
        frames=recording.frames_for(shot.scene.fps),
        unknowns=(body_unknown("ball", "elasticity", 0.4, 1.0),),
        description=f"{shot.name}: {ball} after its last ball contact",
    ).validate()
    notes = {"shot": shot.name, "ball": ball, "start_s": float(tr.t[keep][0])}
    return DatasetRun(name, scene, recording, shot.expected_effects, notes)


def rolling_segments(
    shots: Iterable[DatasetRun], *, count: int | None = None, max_speed: float | None = None
) -> list[DatasetRun]:
    """:func:`rolling_segment` of every ball of each shot in turn, the first ``count`` found
    (default: all)."""
    out: list[DatasetRun] = []
    for shot in shots:
        for ball in shot.recording.tracks:
            seg = rolling_segment(shot, ball, max_speed)
            if seg is None:
                continue
            out.append(seg)
            if count is not None and len(out) >= count:
                return out
    return out


# --------------------------------------------------------------------------- cushions and rolling

#: Time windows on either side of a cushion contact that the velocities in and out are fitted on.
BOUNCE_WINDOW = (0.05, 0.4)  # s


@dataclass(frozen=True)
class CushionBounce:
    """One bounce off a cushion: the run and time, the speed normal to the cushion coming in and
    the tangential velocity coming in (m/s), the restitution ``e_n = |v_n out| / |v_n in|``, the
    share of the tangential velocity kept, and the share of the speed kept."""

    run: str
    t: float
    vn_in: float
    vt_in: float
    e_n: float
    t_kept: float
    speed_kept: float


@dataclass(frozen=True)
class StraightStretch:
    """A stretch of rolling away from the cushions: its deceleration (m/s², positive when
    slowing), start speed (m/s) and duration (s)."""

    run: str
    deceleration: float
    speed: float
    seconds: float


def _cushion_lines() -> tuple[np.ndarray, np.ndarray]:
    """The lowest and highest ball centre on the table, per axis."""
    return np.array([BALL_RADIUS, BALL_RADIUS]), np.array(TABLE) - BALL_RADIUS


def cushion_bounces(run: str, track: Track) -> list[CushionBounce]:
    """Every cushion bounce of ``track`` (a ball in a rolling segment, whose positions touch the
    cushion line when it bounces): velocities from straight-line fits over
    :data:`BOUNCE_WINDOW` before and after the contact, split into the components normal and
    tangential to the cushion. Bounces with another cushion within 2 cm in those windows, fewer
    than 4 samples in either, or coming in nearly along or straight at the cushion are left
    out."""
    lo, hi = _cushion_lines()
    near_s, far_s = BOUNCE_WINDOW
    t, p = track.t, np.stack([track.x, track.y], axis=1)
    near = np.minimum(np.abs(p - lo), np.abs(p - hi))
    out = []
    for axis in (0, 1):
        for wall in (lo[axis], hi[axis]):
            at = np.abs(p[:, axis] - wall) < 1e-3
            for i in np.nonzero(at & ~np.roll(at, 1))[0]:
                th = t[i]
                before = (t > th - far_s) & (t < th - near_s)
                after = (t > th + near_s) & (t < th + far_s)
                if before.sum() < 4 or after.sum() < 4:
                    continue
                if (near[before | after] < 0.02).any():  # another cushion within the windows
                    continue
                vin = np.polyfit(t[before], p[before], 1)[0]
                vout = np.polyfit(t[after], p[after], 1)[0]
                n, tg = axis, 1 - axis
                if abs(vin[n]) < 0.05 or abs(vin[tg]) < 1e-3:
                    continue
                out.append(
                    CushionBounce(
                        run,
                        float(th),
                        vn_in=float(abs(vin[n])),
                        vt_in=float(vin[tg]),
                        e_n=float(abs(vout[n]) / abs(vin[n])),
                        t_kept=float(vout[tg] / vin[tg]),
                        speed_kept=float(np.hypot(*vout) / np.hypot(*vin)),
                    )
                )
    return out


def straight_stretches(run: str, track: Track) -> list[StraightStretch]:
    """Rolling deceleration of ``track`` on each stretch at least 5 cm from every cushion line
    and at least 1 s (12 samples) long that is still rolling at its end: a quadratic fit of the
    path length over time."""
    lo, hi = _cushion_lines()
    t, p = track.t, np.stack([track.x, track.y], axis=1)
    away = (np.minimum(np.abs(p - lo), np.abs(p - hi)) > 0.05).all(axis=1)
    idx = np.nonzero(away)[0]
    out = []
    for part in np.split(idx, np.nonzero(np.diff(idx) > 1)[0] + 1):
        if part.size < 12 or t[part[-1]] - t[part[0]] < 1.0:
            continue
        seconds = t[part[-1]] - t[part[0]]
        path = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p[part], axis=0).T))])
        c2, c1, _ = np.polyfit(t[part] - t[part[0]], path, 2)
        if c1 > 0.05 and c1 + 2 * c2 * seconds > 0.02:  # still rolling at the end
            out.append(StraightStretch(run, float(-2 * c2), float(c1), float(seconds)))
    return out
