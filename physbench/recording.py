"""Recordings: tracked trajectories of real (or simulated) bodies, and their CSV format.

A recording file is CSV with a header naming the columns ``t, body, x, y`` and optionally
``angle`` and ``run``, in any order (SI units: s, m, rad; ``x, y`` is the centre of the body's
shape, as in a :class:`~physbench.trajectory.Trajectory`). Rows may come in any order and each body
may be sampled at its own, irregular times. Rules:

- ``t >= 0``: recording time ``t`` is simulation time ``t`` (a scene starts at 0);
- within one run, a body has at most one sample per time (a repeated time is an error, as is a
  contradictory one: rows are sorted by time, so "time going backwards" can only show as a repeat);
- ``angle`` may be left empty for a body that has no measured angle, but then for all of that
  body's rows in the run;
- ``run`` labels several runs in one file (any non-empty text); without it the file holds one run;
- blank lines and lines starting with ``#`` are skipped, except that comment lines before the
  header may name the fields that were measured (:attr:`Recording.fields`; the other columns then
  hold whatever the tracker filled in): ``# fields: y`` for every run, ``# fields of run "drop 1":
  x, y`` for one run (its label as a JSON string), which overrides the former. Without such a
  line, every field a run's tracks hold counts as measured. ``# accuracy: 0.0021`` states the
  sensor's accuracy in metres (:attr:`Recording.accuracy`) for every run of the file, and
  ``# angle accuracy: 0.003`` that of its angles in radians (:attr:`Recording.angle_accuracy`).

Errors name the line (1 = header), the data row (1 = first row after the header) and the column.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError
from physbench.limits import FPS, MAX_ANGLE, MAX_COORDINATE, MAX_FRAMES, MAX_TIME
from physbench.scene import Scene

if TYPE_CHECKING:
    from physbench.trajectory import Trajectory

REQUIRED_COLUMNS = ("t", "body", "x", "y")
OPTIONAL_COLUMNS = ("angle", "run")
#: Pose fields a recording can hold, and the trajectory state column of each and of its rate.
POSE_FIELDS = ("x", "y", "angle")
_STATE_COLUMN = {"x": (0, 3), "y": (1, 4), "angle": (2, 5)}
#: A comment line naming measured fields: an optional run label (a JSON string), then the fields.
_ACCURACY_LINE = re.compile(r"#\s*accuracy\s*:\s*(\S+?)\s*(?:m)?")
_ANGLE_ACCURACY_LINE = re.compile(r"#\s*angle\s+accuracy\s*:\s*(\S+?)\s*(?:rad)?")
_FIELDS_LINE = re.compile(r'#\s*fields(?:\s+of\s+run\s+(".*"|[^:]*?))?\s*:(.*)')
#: The largest |value| of each numeric column (a scene's limits, physbench.limits), its unit, and
#: why: a value beyond it fits no scene (and its square overflows). Negative times have their own
#: rule.
_LIMITS = {
    "t": (MAX_TIME, "s", f"the longest a scene simulates: {MAX_FRAMES} frames at {FPS[0]:g} fps"),
    "x": (MAX_COORDINATE, "m", "the largest coordinate a scene has"),
    "y": (MAX_COORDINATE, "m", "the largest coordinate a scene has"),
    "angle": (MAX_ANGLE, "rad", "a body at the scenes' fastest spin for their longest time"),
}


class RecordingError(PhysbenchError, ValueError):
    """A malformed recording or a recording that does not fit a simulation."""

    def __init__(
        self,
        message: str,
        *,
        source: str = "",
        line: int | None = None,
        row: int | None = None,
        column: str | None = None,
        comment: bool = False,
    ) -> None:
        self.source, self.line, self.row, self.column, self.reason = (
            source,
            line,
            row,
            column,
            message,
        )
        where = []
        if line is not None:
            part = "comment" if comment else "header" if row is None else f"data row {row}"
            where.append(f"line {line} ({part})")
        if column is not None:
            where.append(f"column {column!r}")
        prefix = f"{source}: " if source else ""
        super().__init__(prefix + (", ".join(where) + ": " if where else "") + message)


@dataclass(frozen=True, eq=False)
class Track:
    """One body's samples in one run, sorted by strictly increasing time ``t`` (s)."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    angle: np.ndarray | None = None

    def __post_init__(self) -> None:
        arrays = {"t": self.t, "x": self.x, "y": self.y}
        if self.angle is not None:
            arrays["angle"] = self.angle
        n = None
        for name, arr in arrays.items():
            a = np.asarray(arr, dtype=float)
            if a.ndim != 1 or a.size == 0 or (n is not None and a.size != n):
                raise RecordingError(
                    f"track {name} must be a non-empty 1-D array as long as t, got shape {a.shape}"
                )
            if not np.isfinite(a).all():
                raise RecordingError(
                    f"track {name} has NaN/inf at sample {int(np.argmin(np.isfinite(a)))}"
                )
            n = a.size
            object.__setattr__(self, name, a)
        bad = np.nonzero(np.diff(self.t) <= 0)[0]
        if bad.size:
            i = int(bad[0]) + 1
            raise RecordingError(
                f"track times must increase strictly; t[{i}] = {self.t[i]!r} follows "
                f"{self.t[i - 1]!r}"
            )
        if self.t[0] < 0:
            raise RecordingError(
                f"track times must be >= 0 (simulations start at t = 0), got {self.t[0]!r}"
            )

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def fields(self) -> tuple[str, ...]:
        return POSE_FIELDS if self.angle is not None else POSE_FIELDS[:2]

    def values(self, name: str) -> np.ndarray:
        if name == "angle" and self.angle is None:
            raise RecordingError("this track has no angle")
        return getattr(self, name)


@dataclass(frozen=True, eq=False)
class Recording:
    """The tracked bodies of one run. ``fields`` names the pose fields that were measured (the
    default of :meth:`residuals`; ``None`` = all the tracks hold), since a loader may have to fill
    in a coordinate the format requires but the sensor did not see. ``accuracy``: the sensor's
    systematic accuracy (m): a model that disagrees with the recording by less is not wrong as
    far as this sensor can tell (0: not stated); ``angle_accuracy``: the same for its angles
    (rad), which is what counts where only angles were measured."""

    tracks: Mapping[str, Track]
    run: str = ""
    fields: tuple[str, ...] | None = None
    source: str = ""
    meta: Mapping[str, object] = field(default_factory=dict)
    accuracy: float = 0.0
    angle_accuracy: float = 0.0

    def __post_init__(self) -> None:
        if not self.tracks:
            raise RecordingError("a recording needs at least one tracked body")
        if not (isinstance(self.accuracy, int | float) and 0 <= self.accuracy < math.inf):
            raise RecordingError(f"accuracy = {self.accuracy!r}: expected metres >= 0")
        ok = isinstance(self.angle_accuracy, int | float) and 0 <= self.angle_accuracy < math.inf
        if not ok:
            raise RecordingError(f"angle_accuracy = {self.angle_accuracy!r}: expected radians >= 0")
        if self.fields is not None:
            for f in self.fields:
                if f not in POSE_FIELDS:
                    raise RecordingError(f"unknown field {f!r}; fields: {', '.join(POSE_FIELDS)}")

    @property
    def bodies(self) -> tuple[str, ...]:
        return tuple(self.tracks)

    def track(self, body: str) -> Track:
        try:
            return self.tracks[body]
        except KeyError:
            from physbench.errors import UnknownNameError

            raise UnknownNameError(f"body of recording {self.run!r}", body, self.tracks) from None

    @property
    def t_end(self) -> float:
        """Time of the last sample of any body (s)."""
        return max(float(tr.t[-1]) for tr in self.tracks.values())

    @property
    def n_samples(self) -> int:
        return sum(len(tr) for tr in self.tracks.values())

    def frames_for(self, fps: float, scale: float = 1.0) -> int:
        """Frames a simulation at ``fps`` needs to cover the recording (``scale``: see
        :class:`~physbench.effects.ClockScale`)."""
        return math.ceil(self.t_end * scale * fps - 1e-9) + 1

    @property
    def measured(self) -> tuple[str, ...]:
        """The fields the residuals compare by default: those named in :attr:`fields` (all
        without it) that a track holds."""
        fields = self.fields if self.fields is not None else POSE_FIELDS
        return tuple(f for f in fields if any(f in tr.fields for tr in self.tracks.values()))

    def _fields(self, fields: Sequence[str] | None) -> tuple[str, ...]:
        if fields is None:
            return self.measured
        for f in fields:
            if f not in POSE_FIELDS:
                raise RecordingError(f"unknown field {f!r}; fields: {', '.join(POSE_FIELDS)}")
            if not any(f in tr.fields for tr in self.tracks.values()):
                raise RecordingError(f"no track of recording {self.run!r} has field {f!r}")
        return tuple(fields)

    # ----------------------------------------------------------------- comparison with a simulation

    def sample(self, traj: Trajectory, *, method: str = "hermite") -> Recording:
        """The simulated poses at this recording's sample times, as a recording of the same
        shape. ``hermite`` interpolates each frame interval with the simulated velocities (error
        O(dt⁴) for smooth motion); ``linear`` ignores them."""
        if method not in ("hermite", "linear"):
            raise RecordingError(f"unknown interpolation {method!r}; known: hermite, linear")
        times = np.asarray(traj.times, dtype=float)
        tracks: dict[str, Track] = {}
        for body, tr in self.tracks.items():
            if body not in traj.bodies:
                raise RecordingError(
                    f"recorded body {body!r} is not simulated; simulated bodies: "
                    f"{', '.join(traj.bodies)}",
                    source=self.source,
                )
            lo, hi = times[0], times[-1]
            tol = 1e-9 * max(1.0, abs(hi))
            if tr.t[0] < lo - tol or tr.t[-1] > hi + tol:
                need = self.frames_for(1.0 / (times[1] - times[0])) if times.size > 1 else "more"
                raise RecordingError(
                    f"run {self.run!r}, body {body!r}: samples span t = {tr.t[0]:g}..{tr.t[-1]:g} "
                    f"s but the simulation covers {lo:g}..{hi:g} s; simulate more frames "
                    f"(at least {need})",
                    source=self.source,
                )
            state = traj.body(body)
            vals = {}
            for f in tr.fields:
                p, v = _STATE_COLUMN[f]
                vals[f] = _interpolate(times, state[:, p], state[:, v], tr.t, method == "hermite")
            tracks[body] = Track(tr.t, vals["x"], vals["y"], vals.get("angle"))
        return Recording(
            tracks,
            run=self.run,
            fields=self.fields,
            source=f"simulated ({traj.engine})",
            meta=self.meta,
        )

    def residuals(
        self,
        traj: Trajectory,
        *,
        fields: Sequence[str] | None = None,
        bodies: Iterable[str] | None = None,
        method: str = "hermite",
    ) -> np.ndarray:
        """Simulated minus recorded, flat, ordered by body, then field, then time; angles wrapped
        to [-π, π). Called by discovery after every simulation (pass the trajectory through the
        measurement effects first). Tracks without a requested field are skipped."""
        names = self.bodies if bodies is None else tuple(bodies)
        want = self._fields(fields)
        sim = self.sample(traj, method=method)
        parts = []
        for body in names:
            rec, got = self.track(body), sim.tracks[body]
            for f in want:
                if f not in rec.fields:
                    continue
                d = got.values(f) - rec.values(f)
                if f == "angle":
                    d = (d + math.pi) % (2 * math.pi) - math.pi
                parts.append(d)
        return np.concatenate(parts) if parts else np.zeros(0)

    def rms(
        self, traj: Trajectory, *, fields: Sequence[str] | None = None, method: str = "hermite"
    ) -> dict[str, float]:
        """Root-mean-square residual per field over all bodies (m or rad)."""
        return {
            f: float(np.sqrt(np.mean(self.residuals(traj, fields=[f], method=method) ** 2)))
            for f in self._fields(fields)
        }

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_trajectory(
        cls,
        traj: Trajectory,
        *,
        times: Mapping[str, np.ndarray] | np.ndarray | None = None,
        bodies: Iterable[str] | None = None,
        angle: bool = True,
        run: str = "",
        fields: tuple[str, ...] | None = None,
    ) -> Recording:
        """A recording of a simulated trajectory, at its frame times or at ``times`` (one array
        for all bodies or one per body), e.g. to make synthetic data for a discovery test."""
        names = traj.bodies if bodies is None else tuple(bodies)
        if times is None:
            tracks = {
                b: Track(traj.times, traj.body(b)[:, 0], traj.body(b)[:, 1], traj.body(b)[:, 2])
                for b in names
            }
        else:
            tracks = {}
            for b in names:
                tb = np.asarray(times[b] if isinstance(times, Mapping) else times, dtype=float)
                zero = np.zeros_like(tb)
                tracks[b] = Track(
                    tb, zero, zero, zero if angle else None
                )  # times only: resampled below
            tracks = dict(cls(tracks).sample(traj).tracks)
        if not angle:
            tracks = {b: Track(tr.t, tr.x, tr.y) for b, tr in tracks.items()}
        return cls(tracks, run=run, fields=fields, source=f"simulated ({traj.engine})")


def _interpolate(
    times: np.ndarray, p: np.ndarray, v: np.ndarray, tq: np.ndarray, hermite: bool
) -> np.ndarray:
    if times.size == 1:
        return np.full(tq.shape, p[0])
    k = np.clip(np.searchsorted(times, tq, side="right") - 1, 0, times.size - 2)
    dt = times[k + 1] - times[k]
    s = np.clip((tq - times[k]) / dt, 0.0, 1.0)
    if not hermite:
        return p[k] + s * (p[k + 1] - p[k])
    s2, s3 = s * s, s * s * s
    return (
        (2 * s3 - 3 * s2 + 1) * p[k]
        + (s3 - 2 * s2 + s) * dt * v[k]
        + (-2 * s3 + 3 * s2) * p[k + 1]
        + (s3 - s2) * dt * v[k + 1]
    )


# --------------------------------------------------------------------------- CSV


def _known_bodies(bodies: Scene | Iterable[str] | None) -> tuple[str, ...] | None:
    if bodies is None:
        return None
    return bodies.body_names if isinstance(bodies, Scene) else tuple(bodies)


def _declared_accuracy(text: str, source: str, *, angle: bool = False) -> float:
    """The ``# accuracy: METRES`` line before the header (``angle``: the ``# angle accuracy:
    RADIANS`` line; 0 without one)."""
    pattern, unit = (_ANGLE_ACCURACY_LINE, "radians") if angle else (_ACCURACY_LINE, "metres")
    example = "# angle accuracy: 0.003" if angle else "# accuracy: 0.002"
    for line, raw in enumerate(io.StringIO(text), start=1):
        stripped = raw.strip()
        if stripped and not stripped.startswith("#"):
            break
        m = pattern.fullmatch(stripped)
        if m is None:
            continue
        try:
            value = float(m.group(1))
        except ValueError:
            value = math.nan
        if not 0 <= value < math.inf:
            raise RecordingError(
                f"{'angle ' if angle else ''}accuracy {m.group(1)!r} is not {unit} >= 0; "
                f"expected e.g. {example}",
                source=source,
                line=line,
                comment=True,
            )
        return value
    return 0.0


def _declared_fields(
    text: str, source: str
) -> tuple[dict[str | None, tuple[tuple[str, ...], int]], str]:
    """The ``# fields`` lines before the header, as run label (``None``: every run) -> (fields,
    line), and ``text`` with the comment lines before the header blanked: the CSV reader would
    take a quote in them for the start of a quoted cell."""
    out: dict[str | None, tuple[tuple[str, ...], int]] = {}
    skipped = 0

    def bad(msg: str, line: int) -> RecordingError:
        return RecordingError(msg, source=source, line=line, comment=True)

    for line, raw in enumerate(io.StringIO(text), start=1):
        stripped = raw.strip()
        if stripped and not stripped.startswith("#"):
            break  # the header: comments after it are skipped as CSV rows
        skipped += len(raw)
        m = _FIELDS_LINE.fullmatch(stripped)
        if m is None:
            continue
        run: str | None = None
        if m.group(1) is not None:
            try:
                run = json.loads(m.group(1))
            except json.JSONDecodeError:
                run = None
            if not isinstance(run, str):
                raise bad(
                    f"run label {m.group(1)} is not a JSON string; expected e.g. "
                    '# fields of run "drop 1": x, y',
                    line,
                )
        names = tuple(f.strip() for f in m.group(2).split(","))
        names = () if names == ("",) else names
        for f in names:
            if f not in POSE_FIELDS:
                raise bad(f"unknown field {f!r}; fields are {', '.join(POSE_FIELDS)}", line)
        if run in out:
            which = "every run" if run is None else f"run {run!r}"
            raise bad(f"fields of {which} given twice (also at line {out[run][1]})", line)
        out[run] = (names, line)
    return out, "\n" * text.count("\n", 0, skipped) + text[skipped:]


def _csv_rows(reader: Iterator[list[str]], source: str) -> Iterator[list[str]]:
    """The rows of ``reader``, with its ``csv.Error`` (a field over the csv module's size limit)
    raised as a :class:`RecordingError` naming the line."""
    while True:
        try:
            yield next(reader)
        except StopIteration:
            return
        except csv.Error as exc:
            line = getattr(reader, "line_num", 0)
            raise RecordingError(
                f"line {line}: not readable as CSV ({exc}); a cell holds at most "
                f"{csv.field_size_limit()} characters",
                source=source,
            ) from None


def parse_recordings(
    text: str, *, bodies: Scene | Iterable[str] | None = None, source: str = "<string>"
) -> list[Recording]:
    """Parse recording CSV text into one :class:`Recording` per run, in order of first
    appearance. ``bodies`` (a scene or names) makes an unknown body name an error."""
    known = _known_bodies(bodies)
    text = text.removeprefix("\ufeff")
    accuracy = _declared_accuracy(text, source)
    angle_accuracy = _declared_accuracy(text, source, angle=True)
    declared, text = _declared_fields(text, source)
    runs = _read_samples(text, source, known).tracks()
    _check_declared_runs(declared, runs, source)
    every = declared.get(None, (None, 0))[0]
    return [
        Recording(
            tracks,
            run=run,
            fields=declared.get(run, (every, 0))[0],
            source=source,
            accuracy=accuracy,
            angle_accuracy=angle_accuracy,
        )
        for run, tracks in runs.items()
    ]


def _cell_error(
    msg: str, source: str, column: str | None, line: int, row: int | None
) -> RecordingError:
    """An error at ``column`` of ``line`` (the header when ``row`` is None)."""
    return RecordingError(msg, source=source, line=line, row=row, column=column)


def _read_samples(text: str, source: str, known: tuple[str, ...] | None) -> _Samples:
    """Read the header and every data row of the CSV ``text`` (comment lines blanked)."""
    reader = csv.reader(io.StringIO(text))
    samples: _Samples | None = None
    row_no = 0
    for cells in _csv_rows(reader, source):
        line = reader.line_num
        if not cells or all(not c.strip() for c in cells) or cells[0].lstrip().startswith("#"):
            continue
        cells = [c.strip() for c in cells]
        if samples is None:
            samples = _Samples(source, known, cells, line, _columns(cells, line, source))
            continue
        row_no += 1
        samples.add(cells, line, row_no)
    if samples is None:
        raise _cell_error(
            f"empty file; expected a header with columns {','.join(REQUIRED_COLUMNS)} (optionally "
            "angle, run)",
            source,
            "t",
            1,
            None,
        )
    if not samples.groups:
        raise _cell_error("no data rows after the header", source, "t", samples.header_line + 1, 1)
    return samples


def _columns(header: list[str], line: int, source: str) -> dict[str, int]:
    """The index of each column the header names; unknown, duplicate and missing columns are
    errors."""
    col: dict[str, int] = {}
    for i, name in enumerate(header):
        if name not in REQUIRED_COLUMNS + OPTIONAL_COLUMNS:
            raise _cell_error(
                f"unknown column name {name!r}; columns are {', '.join(REQUIRED_COLUMNS)} "
                "and optionally "
                f"{', '.join(OPTIONAL_COLUMNS)}",
                source,
                name or f"#{i + 1}",
                line,
                None,
            )
        if name in col:
            msg = f"duplicate column (also column {col[name] + 1})"
            raise _cell_error(msg, source, name, line, None)
        col[name] = i
    for name in REQUIRED_COLUMNS:
        if name not in col:
            raise _cell_error(
                f"missing required column; the header has {', '.join(header)} but needs "
                f"{', '.join(REQUIRED_COLUMNS)}",
                source,
                name,
                line,
                None,
            )
    return col


@dataclass(frozen=True)
class _Sample:
    """One data row's values (``angle`` NaN when its cell is empty)."""

    run: str
    body: str
    t: float
    x: float
    y: float
    angle: float
    has_angle: bool


@dataclass
class _Samples:
    """The data rows read so far, grouped by (run, body), with what the checks across rows need:
    whether each body's rows give an angle (and the first line that said so) and the line of each
    of its times."""

    source: str
    known: tuple[str, ...] | None
    header: list[str]
    header_line: int
    col: dict[str, int]
    groups: dict[tuple[str, str], dict[str, list[float]]] = field(default_factory=dict)
    seen_times: dict[tuple[str, str], dict[float, int]] = field(default_factory=dict)
    angle_state: dict[tuple[str, str], tuple[bool, int]] = field(default_factory=dict)

    def err(self, msg: str, column: str | None, line: int, row: int | None) -> RecordingError:
        return _cell_error(msg, self.source, column, line, row)

    def add(self, cells: list[str], line: int, row_no: int) -> None:
        """Check one data row against the header and the rows before it, and keep its sample."""
        s = self._sample(cells, line, row_no)
        key = (s.run, s.body)
        if key in self.angle_state and self.angle_state[key][0] != s.has_angle:
            first_with, first_line = self.angle_state[key]
            raise self.err(
                f"angle is {'given' if first_with else 'empty'} for body {s.body!r} in run "
                f"{s.run!r} at line {first_line} "
                f"but {'given' if s.has_angle else 'empty'} here; give it in all of the body's "
                "rows or in none",
                "angle",
                line,
                row_no,
            )
        self.angle_state.setdefault(key, (s.has_angle, line))
        times = self.seen_times.setdefault(key, {})
        if s.t in times:
            raise self.err(
                f"t = {s.t!r} repeats for body {s.body!r} in run {s.run!r} (also at line "
                f"{times[s.t]}); a body has one sample per time in a run",
                "t",
                line,
                row_no,
            )
        times[s.t] = line
        g = self.groups.setdefault(key, {"t": [], "x": [], "y": [], "angle": []})
        g["t"].append(s.t)
        g["x"].append(s.x)
        g["y"].append(s.y)
        g["angle"].append(s.angle)

    def _sample(self, cells: list[str], line: int, row_no: int) -> _Sample:
        """The values of one data row, each checked on its own."""
        header, col, known = self.header, self.col, self.known
        if len(cells) != len(header):
            column = header[len(cells)] if len(cells) < len(header) else f"#{len(header) + 1}"
            raise self.err(
                f"expected {len(header)} values ({', '.join(header)}), got {len(cells)}",
                column,
                line,
                row_no,
            )
        body = cells[col["body"]]
        if not body:
            raise self.err("empty body name", "body", line, row_no)
        if known is not None and body not in known:
            raise self.err(
                f"unknown body {body!r}; the scene's bodies are {', '.join(known)}",
                "body",
                line,
                row_no,
            )
        run = cells[col["run"]] if "run" in col else ""
        if "run" in col and not run:
            raise self.err("empty run label", "run", line, row_no)
        t = self._number(cells, "t", line, row_no)
        if t < 0:
            msg = f"t = {t!r}: times must be >= 0 (simulations start at t = 0)"
            raise self.err(msg, "t", line, row_no)
        x, y = self._number(cells, "x", line, row_no), self._number(cells, "y", line, row_no)
        has_angle = "angle" in col and cells[col["angle"]] != ""
        a = self._number(cells, "angle", line, row_no) if has_angle else math.nan
        return _Sample(run, body, t, x, y, a, has_angle)

    def _number(self, cells: list[str], name: str, line: int, row_no: int) -> float:
        """The finite number in column ``name``, within its limit (:data:`_LIMITS`)."""
        raw = cells[self.col[name]]
        try:
            v = float(raw)
        except ValueError:
            raise self.err(f"{raw!r} is not a number", name, line, row_no) from None
        if not math.isfinite(v):
            raise self.err(f"{raw!r}: values must be finite numbers", name, line, row_no)
        most, unit, why = _LIMITS[name]
        if abs(v) > most and not (name == "t" and v < 0):
            which = f"{name} <= {most:g}" if name == "t" else f"|{name}| <= {most:g}"
            raise self.err(
                f"{name} = {v:g} {unit} is beyond the scene limit {which} {unit} ({why})",
                name,
                line,
                row_no,
            )
        return v

    def tracks(self) -> dict[str, dict[str, Track]]:
        """Each body's samples as a track in time order, by run, in order of first appearance."""
        runs: dict[str, dict[str, Track]] = {}
        for (run, body), g in self.groups.items():
            t = np.asarray(g["t"])
            order = np.argsort(t, kind="stable")
            ang = np.asarray(g["angle"])[order] if self.angle_state[(run, body)][0] else None
            runs.setdefault(run, {})[body] = Track(
                t[order], np.asarray(g["x"])[order], np.asarray(g["y"])[order], ang
            )
        return runs


def _check_declared_runs(
    declared: Mapping[str | None, tuple[tuple[str, ...], int]],
    runs: Mapping[str, object],
    source: str,
) -> None:
    """A ``# fields of run`` line must name a run that has rows."""
    for run, (_, line) in declared.items():
        if run is not None and run not in runs:
            have = ", ".join(repr(r) for r in runs)
            raise RecordingError(
                f"fields of run {run!r}, but no row is of that run; runs: {have}",
                source=source,
                line=line,
                comment=True,
            )


def read_recordings(
    path: str | Path, *, bodies: Scene | Iterable[str] | None = None
) -> list[Recording]:
    """Read a recording CSV file: one :class:`Recording` per run (see the module docstring)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise RecordingError(f"not UTF-8 text: {exc}", source=str(p)) from None
    return parse_recordings(text, bodies=bodies, source=str(p))


def read_recording(
    path: str | Path, *, bodies: Scene | Iterable[str] | None = None, run: str | None = None
) -> Recording:
    """Read one run: ``run`` names it; without ``run`` the file must hold exactly one."""
    recs = read_recordings(path, bodies=bodies)
    if run is None:
        if len(recs) != 1:
            raise RecordingError(
                f"file holds {len(recs)} runs ({', '.join(r.run for r in recs)}); pass run=...",
                source=str(path),
            )
        return recs[0]
    for r in recs:
        if r.run == run:
            return r
    raise RecordingError(
        f"no run {run!r}; runs: {', '.join(r.run for r in recs)}", source=str(path)
    )


def format_recordings(recordings: Sequence[Recording]) -> str:
    """CSV text of ``recordings`` (one run each), exact to the last bit (``repr`` floats), with a
    ``# fields`` line for each run whose measured fields are named."""
    if not recordings:
        raise RecordingError("nothing to write: no recordings")
    labels = [r.run for r in recordings]
    with_run = len(recordings) > 1 or labels[0] != ""
    if with_run and (len(set(labels)) != len(labels) or "" in labels):
        raise RecordingError(
            f"each run needs a distinct, non-empty label to share a file; labels: {labels}"
        )
    for name in (*labels, *(b for r in recordings for b in r.tracks)):
        if name != name.strip():
            raise RecordingError(
                f"name {name!r} starts or ends with white space, which a reader strips; give it "
                "without"
            )
    with_angle = any(tr.angle is not None for r in recordings for tr in r.tracks.values())
    buf = io.StringIO()
    accuracy = max(r.accuracy for r in recordings)
    if accuracy > 0:  # one line for the file: the coarsest of its runs
        buf.write(f"# accuracy: {accuracy!r}\n")
    angle_accuracy = max(r.angle_accuracy for r in recordings)
    if angle_accuracy > 0:
        buf.write(f"# angle accuracy: {angle_accuracy!r}\n")
    for r in recordings:
        if r.fields is not None:
            which = f" of run {json.dumps(r.run)}" if with_run else ""
            buf.write(f"# fields{which}: {', '.join(r.fields)}\n")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(
        ["t", "body", "x", "y", *(["angle"] if with_angle else []), *(["run"] if with_run else [])]
    )
    for r in recordings:
        for body, tr in r.tracks.items():
            for i in range(len(tr)):
                row = [repr(float(tr.t[i])), body, repr(float(tr.x[i])), repr(float(tr.y[i]))]
                if with_angle:
                    row.append(repr(float(tr.angle[i])) if tr.angle is not None else "")
                if with_run:
                    row.append(r.run)
                w.writerow(row)
    return buf.getvalue()


def write_recordings(path: str | Path, recordings: Sequence[Recording] | Recording) -> None:
    """Write one or several runs to a CSV file that :func:`read_recordings` reads back exactly."""
    recs = [recordings] if isinstance(recordings, Recording) else list(recordings)
    Path(path).write_text(format_recordings(recs), encoding="utf-8")
