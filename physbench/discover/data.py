"""What discovery fits: runs (a scene plus its recording or frames), loaded from files or data sets,
and how each run is split into the part a model is fitted on and the part it is scored on.

A run's scene reproduces the setup (geometry, initial state, the base model's unknowns); its data
are either a :class:`~physbench.recording.Recording` (tracked trajectories, trajectory-space loss)
or observed frames ``(T, C, H, W)`` (image loss with a renderer chosen by name).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from physbench.errors import PhysbenchError, counted
from physbench.recording import Recording, Track

if TYPE_CHECKING:
    from physbench.calibration import Calibration
    from physbench.datasets.recorded_run import DatasetRun
    from physbench.scene import Scene

#: Fewest samples (recordings) or frames (frames) a run needs in its fitted and held-out parts.
MIN_FIT_SAMPLES = 6
MIN_HELD_SAMPLES = 3
SPLITS = ("time", "runs", "auto")


class DiscoverError(PhysbenchError, ValueError):
    """Bad input to discovery: names the run, file, option or value and what would be accepted."""


@dataclass(frozen=True, eq=False)
class Run:
    """One observed run: ``scene`` reproduces its setup; exactly one of ``recording`` and
    ``frames`` holds the data. The scene's frame count is set to cover the data."""

    name: str
    scene: Scene
    recording: Recording | None = None
    frames: np.ndarray | None = None
    source: str = ""

    def __post_init__(self) -> None:
        if (self.recording is None) == (self.frames is None):
            raise DiscoverError(f"run {self.name!r}: give exactly one of a recording and frames")
        names = self.scene.body_names
        if self.recording is not None:
            missing = [b for b in self.recording.bodies if b not in names]
            if missing:
                raise DiscoverError(
                    f"run {self.name!r}: recorded bodies {missing} are not in scene "
                    f"{self.scene.name!r} "
                    f"(bodies: {', '.join(names)})"
                )
            frames = self.recording.frames_for(self.scene.fps)
        else:
            f = np.asarray(self.frames)
            if f.ndim != 4 or f.shape[0] < 2:
                raise DiscoverError(
                    f"run {self.name!r}: frames must be (T, C, H, W) with T >= 2, got shape "
                    f"{f.shape}"
                )
            frames = int(f.shape[0])
        if self.scene.frames != frames:
            object.__setattr__(self, "scene", replace(self.scene, frames=frames))

    @property
    def t_end(self) -> float:
        if self.recording is not None:
            return self.recording.t_end
        return (self.scene.frames - 1) / self.scene.fps

    @property
    def kind(self) -> str:
        return "recording" if self.recording is not None else "frames"


def runs_from_dataset(runs: Iterable[DatasetRun]) -> list[Run]:
    """One discovery run per data-set run (:func:`physbench.datasets.load`)."""
    return [Run(r.name, r.scene, recording=r.recording, source=r.recording.source) for r in runs]


def load_runs(
    recording: str | Path,
    scene: Scene | str | Path,
    *,
    run: str | None = None,
    calibration: Calibration | str | Path | None = None,
    background: str | Path | None = None,
    start: float | None = None,
    end: float | None = None,
    track_out: str | Path | None = None,
    allow_gaps: bool = False,
    progress: bool = False,
    transfer: str | None = None,
    capture_fps: float | None = None,
) -> list[Run]:
    """Runs from a recording file (``.csv``: tracked trajectories, one run per ``run`` label;
    ``.npz``: observed frames under key ``frames``; ``.trz``/``.trk``: the hand-marked points of a
    Tracker project, :mod:`physbench.tracker_files`; a video file or a folder of images: tracked
    first, see :func:`~physbench.video.track.track_video`) and a scene (object or ``.toml`` file)
    that every run shares. ``run`` keeps one run of a multi-run CSV. ``calibration``,
    ``background``, ``start``, ``end``, ``allow_gaps``, ``transfer`` and ``capture_fps`` apply to
    a video only (a body lost in more than the tracker's share of its frames is an error unless
    ``allow_gaps``; ``transfer``: how its pixels encode light; ``capture_fps``: the rate a
    slow-motion file was filmed at; :func:`~physbench.video.track.track_video`);
    ``track_out`` writes its tracks as a recording CSV."""
    from physbench.scene_toml import load_scene
    from physbench.tracker_files import is_tracker_file, tracker_path
    from physbench.video.reader import VIDEO_SUFFIXES, is_video

    sc = scene if not isinstance(scene, str | Path) else load_scene(scene)
    sc.validate()
    path = Path(recording)
    video = is_video(path)
    file = tracker_path(path)[0] if is_tracker_file(path) else path  # ARCHIVE.trz:PROJECT.trk
    if not file.exists() or (not video and not file.is_file()):
        raise DiscoverError(
            f"recording file {str(file)!r} does not exist; expected a .csv recording, .npz "
            "frames, a Tracker project (.trz, .trk) or a video "
            f"({', '.join(VIDEO_SUFFIXES)}, or a folder of images)"
        )
    stray = {
        "calibration": calibration,
        "background": background,
        "start": start,
        "end": end,
        "track_out": track_out,
        "allow_gaps": allow_gaps or None,
        "transfer": transfer,
        "capture_fps": capture_fps,
    }
    stray_given = [k for k, v in stray.items() if v is not None]
    if stray_given and not video:
        raise DiscoverError(
            f"{', '.join(stray_given)} apply to a video only; {str(path)!r} is not a video "
            f"({', '.join(VIDEO_SUFFIXES)}, or a folder of images)"
        )
    if video:
        return [
            _video_run(
                path,
                sc,
                calibration,
                background,
                start,
                end,
                track_out,
                allow_gaps=allow_gaps,
                progress=progress,
                transfer=transfer,
                capture_fps=capture_fps,
            )
        ]
    if is_tracker_file(path):
        return [_tracker_run(path, sc)]
    suffix = path.suffix.lower()
    if suffix == ".csv":
        from physbench.recording import read_recordings

        recs = read_recordings(path, bodies=sc)
        if run is not None:
            recs = [r for r in recs if r.run == run]
            if not recs:
                labels = [r.run for r in read_recordings(path, bodies=sc)]
                raise DiscoverError(f"{path}: no run {run!r}; runs: {', '.join(labels)}")
        return [Run(r.run or path.stem, sc, recording=r, source=str(path)) for r in recs]
    if suffix == ".npz":
        from physbench.observation import load_observation

        obs = load_observation(path)
        return [
            Run(path.stem, sc, frames=np.asarray(obs.frames, dtype=np.float32), source=str(path))
        ]
    raise DiscoverError(
        f"recording {str(path)!r}: unknown format {suffix or '(no suffix)'!r}; expected .csv "
        "(tracked trajectories t,body,x,y[,angle][,run]), .npz (frames), a Tracker project "
        "(.trz, .trk) or a video "
        f"({', '.join(VIDEO_SUFFIXES)}, or a folder of images)"
    )


def _tracker_run(path: Path, scene: Scene) -> Run:
    """The hand-marked points of a Tracker project as one run: its tracks named after the
    scene's bodies (a project may mark more than the scene models, such as both ends of a
    spinning body, or a second ball; those left out are named in a
    :class:`~physbench.errors.PhysbenchWarning`)."""
    import warnings
    from dataclasses import replace

    from physbench.errors import PhysbenchWarning
    from physbench.tracker_files import read_tracker_project

    rec = read_tracker_project(path).recording()
    kept = [b for b in rec.bodies if b in scene.body_names]
    left = [b for b in rec.bodies if b not in scene.body_names]
    if not kept:
        raise DiscoverError(
            f"{path}: no Tracker track is a body of scene {scene.name!r} (tracks: "
            f"{', '.join(map(repr, left))}; bodies: {', '.join(scene.body_names)}); name the "
            "scene's body after the track (physbench scene new --from the project does)"
        )
    if left:
        warnings.warn(
            f"{path}: Tracker track{'s' if len(left) > 1 else ''} {', '.join(map(repr, left))} "
            f"left out: not a body of scene {scene.name!r}",
            PhysbenchWarning,
            stacklevel=3,
        )
        rec = replace(rec, tracks={b: rec.tracks[b] for b in kept})
    return Run(path.stem, scene, recording=rec, source=str(path))


def _video_run(
    path: Path,
    scene: Scene,
    calibration: Calibration | str | Path | None,
    background: str | Path | None,
    start: float | None,
    end: float | None,
    track_out: str | Path | None,
    *,
    allow_gaps: bool,
    progress: bool,
    transfer: str | None = None,
    capture_fps: float | None = None,
) -> Run:
    """Track the scene's bodies through a video into one run; the summary goes to stderr."""
    import sys

    from physbench.calibration import load_calibration
    from physbench.recording import write_recordings
    from physbench.video.track import track_video

    cal = load_calibration(calibration) if isinstance(calibration, str | Path) else calibration
    tracked = track_video(
        path,
        scene,
        cal,
        start=start,
        end=end,
        background=background,
        allow_gaps=allow_gaps,
        progress=progress,
        transfer=transfer,
        capture_fps=capture_fps,
    )
    if progress:
        print(tracked.summary.format(), file=sys.stderr)
    if track_out is not None:
        write_recordings(track_out, tracked.recording)
        if progress:
            print(f"wrote {track_out}", file=sys.stderr)
    return Run(path.stem, scene, recording=tracked.recording, source=str(path))


# --------------------------------------------------------------------------- splitting


@dataclass(frozen=True, eq=False)
class Part:
    """The samples of one run used for one purpose: a sub-recording, or frame indices."""

    run: int
    recording: Recording | None = None
    frames: np.ndarray | None = None  # indices into the run's frames
    t_end: float = 0.0

    @property
    def size(self) -> int:
        if self.recording is not None:
            return self.recording.n_samples
        return 0 if self.frames is None else int(self.frames.size)


def sub_recording(rec: Recording, lo: float, hi: float) -> Recording | None:
    """The samples with ``lo < t <= hi`` (``lo = -inf`` keeps the start), or None when empty."""
    tracks = {}
    for body, tr in rec.tracks.items():
        keep = (tr.t > lo) & (tr.t <= hi)
        if keep.any():
            tracks[body] = Track(
                tr.t[keep], tr.x[keep], tr.y[keep], None if tr.angle is None else tr.angle[keep]
            )
    if not tracks:
        return None
    return Recording(tracks, run=rec.run, fields=rec.fields, source=rec.source, meta=rec.meta)


def _cut(run: Run, index: int, t_cut: float, what: str) -> tuple[Part, Part]:
    t_cut += 1e-9 * max(1.0, abs(t_cut))  # a sample at the cut belongs to the fitted part
    if run.recording is not None:
        first, held = (
            sub_recording(run.recording, -math.inf, t_cut),
            sub_recording(run.recording, t_cut, math.inf),
        )
        n_fit = 0 if first is None else first.n_samples
        n_held = 0 if held is None else held.n_samples
        a = Part(index, recording=first, t_end=t_cut if first is None else first.t_end)
        b = Part(index, recording=held, t_end=run.t_end)
    else:
        k = math.floor(t_cut * run.scene.fps + 1e-9)
        n = run.scene.frames
        a = Part(index, frames=np.arange(0, k + 1), t_end=k / run.scene.fps)
        b = Part(index, frames=np.arange(k + 1, n), t_end=(n - 1) / run.scene.fps)
        n_fit, n_held = a.size, b.size
    if n_fit < MIN_FIT_SAMPLES or n_held < MIN_HELD_SAMPLES:
        raise DiscoverError(
            f"run {run.name!r}: splitting at t = {t_cut:.4g} s ({what}) leaves "
            f"{counted(n_fit, 'sample')} to fit and {n_held} to score; need at least "
            f"{MIN_FIT_SAMPLES} and {MIN_HELD_SAMPLES}: record a longer run or change --holdout"
        )
    return a, b


def _whole(run: Run, index: int) -> Part:
    if run.recording is not None:
        return Part(index, recording=run.recording, t_end=run.t_end)
    return Part(index, frames=np.arange(run.scene.frames), t_end=run.t_end)


def _start(run: Run) -> float:
    if run.recording is not None:
        return min(float(tr.t[0]) for tr in run.recording.tracks.values())
    return 0.0


@dataclass(frozen=True, eq=False)
class Split:
    """How the runs divide into fitted and held-out data.

    ``fit``: parts the shared parameters are fitted on; ``lead``: the opening parts of held-out
    runs, on which only those runs' own nuisance parameters (initial state) are fitted;
    ``held``: the parts every model is scored on. ``kind`` is ``"time"`` (every run's later part
    is held out) or ``"runs"`` (whole runs are held out, after a lead-in).
    """

    kind: str
    fraction: float
    fit: tuple[Part, ...]
    lead: tuple[Part, ...]
    held: tuple[Part, ...]
    train_runs: tuple[int, ...]
    test_runs: tuple[int, ...]

    def describe(self, runs: Sequence[Run]) -> str:
        if self.kind == "time":
            return f"each run's last {self.fraction:.0%} of its duration held out"
        names = ", ".join(runs[i].name for i in self.test_runs)
        return (
            f"runs {names} held out (their first {1 - self.fraction:.0%} fits only their "
            "initial state)"
        )


def make_split(
    runs: Sequence[Run], holdout: float = 0.3, kind: str = "auto", lead: float = 0.25
) -> Split:
    """Split ``runs``: ``"time"`` holds out the last ``holdout`` of every run; ``"runs"`` holds out
    the last ``round(holdout · runs)`` runs (at least one), whose first ``lead`` fits only their own
    initial state; ``"auto"`` is ``"runs"`` with 3 or more runs, else ``"time"``."""
    if kind not in SPLITS:
        raise DiscoverError(f"split = {kind!r}: expected one of {', '.join(SPLITS)}")
    if (
        isinstance(holdout, bool)
        or not isinstance(holdout, int | float)
        or not 0.05 <= holdout <= 0.8
    ):
        raise DiscoverError(
            f"holdout = {holdout!r}: expected a fraction in [0.05, 0.8] of the data to hold out"
        )
    if not runs:
        raise DiscoverError("no runs to discover from")
    names = [r.name for r in runs]
    if len(set(names)) != len(names):
        raise DiscoverError(f"run names must be distinct; got {names}")
    if kind == "auto":
        kind = "runs" if len(runs) >= 3 else "time"
    if kind == "runs" and len(runs) < 2:
        raise DiscoverError(
            f"split = 'runs' needs at least 2 runs; got {len(runs)} ({', '.join(names)}); "
            "use split='time'"
        )
    if kind == "time":
        fit, held = [], []
        for i, r in enumerate(runs):
            t0 = _start(r)
            a, b = _cut(r, i, t0 + (1.0 - holdout) * (r.t_end - t0), f"last {holdout:.0%} held out")
            fit.append(a)
            held.append(b)
        idx = tuple(range(len(runs)))
        return Split("time", float(holdout), tuple(fit), (), tuple(held), idx, idx)
    n_test = min(len(runs) - 1, max(1, round(holdout * len(runs))))
    train, test = tuple(range(len(runs) - n_test)), tuple(range(len(runs) - n_test, len(runs)))
    leads, held = [], []
    for i in test:
        r = runs[i]
        t0 = _start(r)
        a, b = _cut(r, i, t0 + lead * (r.t_end - t0), f"first {lead:.0%} fits the initial state")
        leads.append(a)
        held.append(b)
    return Split(
        "runs",
        1.0 - float(lead),
        tuple(_whole(runs[i], i) for i in train),
        tuple(leads),
        tuple(held),
        train,
        test,
    )
