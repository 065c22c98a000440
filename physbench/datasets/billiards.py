"""A real three-cushion billiards match (Dogan, 2022-12-25): 182 shots, tracked ball centres.

Each shot becomes a :class:`~physbench.datasets.Case`: a top-down scene (gravity 0) of the 2.84 ×
1.42 m table, its four cushions as thick segments whose inner surface is the table edge, and the
three balls (``white``, ``yellow``, ``red``) at rest at their first tracked positions. The cue
strike is an impulse on the cue ball (see :func:`cue_strike`); tracking starts slightly before it.
The recording has ``x, y``; balls are only sampled while they move.

The plain model misses rolling resistance, cushion losses and spin (see PROVENANCE.md);
:func:`rolling_decelerations` measures the first from the tracks.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from physbench.datasets import Case, DatasetError, data_dir, data_file
from physbench.recording import Recording, Track
from physbench.scene import Body, Circle, Force, Scene, Segment

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
            f"{path}: expected 6 columns shot_index,shot_id,ball_id,t_s,x_m,y_m, got {data.shape[1]}"
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
) -> list[Case]:
    """One case per shot (``shots``: shot indices 0-181, default all)."""
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
            description=f"three-cushion shot {shot} (tracking id {shot_id}), cue ball {cue}, top-down",
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
            Case(
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
