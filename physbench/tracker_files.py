"""Project files of Tracker, the video analysis tool of Open Source Physics: a calibration and
hand-marked points, read into physbench's pixels, metres and seconds.

A ``.trk`` file is Tracker's XML (``<object class=...>`` elements holding ``<property
name=... type=...>`` elements); a ``.trz`` file is a zip archive holding one (or more) ``.trk``
files and usually the video. :func:`read_tracker_project` reads:

- **the coordinate system** (``coords``: an ``ImageCoordSystem``): the origin ``xorigin``,
  ``yorigin`` (Tracker image pixels), the x axis' ``angle`` (degrees, counter-clockwise as seen
  in the picture, stored in degrees in the file), and ``xscale``, ``yscale`` (image pixels per
  length unit), with the ``length_unit`` (m, cm, mm, km, in, ft or yd; a file that names none is
  taken as metres, and :attr:`TrackerProject.notes` says so). Tracker maps a world point to the
  image by ``X = xs (x cos a - y sin a) + X0``, ``Y = -ys (x sin a + y cos a) + Y0``. A tape
  measure, calibration points or an offset origin only set these values, so they are what is
  read. A coordinate system that moves from frame to frame is refused (physbench needs a fixed
  camera).
- **the pixel convention**: Tracker draws the video with the top-left corner of its top-left
  pixel at ``(0, 0)``, so a pixel's centre is at ``(i + 0.5, j + 0.5)``; physbench puts pixel
  centres at integers. physbench pixel ``(u, v)`` is Tracker image point ``(u + 0.5, v + 0.5)``
  (:data:`PIXEL_OFFSET`).
- **the clock**: frame ``n`` is at ``starttime + (n - startframe) delta_t`` (ms; ``startframe``
  and ``starttime`` from the ``VideoClip``, ``delta_t`` from the clip control), as Tracker itself
  times it. physbench's recording time 0 is the first marked frame (recordings start at 0).
- **hand-marked points**: every ``PointMass`` track (not model particles or other tracks), one
  body per track name, its marks ``framedata[n]`` (Tracker image pixels in frame ``n``) and its
  ``mass`` (with ``mass_unit``: kg, g or mg; Tracker's 1 where none is stated).
- **centres of mass**: a ``CenterOfMass`` track (the point a teacher follows on a spinning or
  jointed body whose ends were marked: a diabolo, a thrown bat) is computed as Tracker computes
  it: the mass-weighted mean of the point masses it names, in the frames where all of them are
  marked, with their total mass. Its file stores no points of its own.

Video filters that move pixels (perspective, radial distortion, rotation, resize) put Tracker's
image coordinates in the filtered picture: such a project still gives a recording, but
:meth:`TrackerProject.homography` refuses it, since its pixels are not the video's.

:func:`project_video` finds the video a project names (inside a ``.trz``, or beside a ``.trk``),
an image sequence (Tracker names its first image) as a folder of its images, so that ``physbench
track`` can follow the bodies through a teacher's own project.
"""

from __future__ import annotations

import math
import posixpath
import re
import shutil
import zipfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING
from xml.etree import ElementTree

import numpy as np

from physbench.errors import PhysbenchError

if TYPE_CHECKING:
    from physbench.recording import Recording

#: physbench pixel ``(u, v)`` is Tracker image point ``(u + PIXEL_OFFSET, v + PIXEL_OFFSET)``.
PIXEL_OFFSET = 0.5
#: Metres per length unit Tracker files name.
LENGTH_UNITS = {
    "m": 1.0,
    "cm": 0.01,
    "mm": 0.001,
    "km": 1000.0,
    "in": 0.0254,
    "ft": 0.3048,
    "yd": 0.9144,
}
MASS_UNITS = {"kg": 1.0, "g": 1e-3, "mg": 1e-6}
#: How well a person marks a point in a frame (px): the accuracy a project's recording states.
MARK_ACCURACY_PX = 1.0
#: Video filters that move pixels, so Tracker's coordinates are not the video's.
GEOMETRIC_FILTERS = (
    "PerspectiveFilter",
    "RadialDistortionFilter",
    "BarrelPincushionFilter",
    "RotateFilter",
    "ResizeFilter",
)
#: Largest .trk file read (bytes).
MAX_TRK_BYTES = 64 * 1024 * 1024
TRACKER_SUFFIXES = (".trz", ".trk")
_POINT_MASS = "org.opensourcephysics.cabrillo.tracker.PointMass"
_CENTRE_OF_MASS = "org.opensourcephysics.cabrillo.tracker.CenterOfMass"
#: Tracker's mass of a point mass whose file states none.
DEFAULT_MASS = 1.0


class TrackerFileError(PhysbenchError, ValueError):
    """A Tracker project physbench cannot read: names the file and the element or value."""


@dataclass(frozen=True)
class Marks:
    """One hand-marked track: frame numbers and Tracker image points ``(X, Y)`` (px)."""

    frames: np.ndarray
    x: np.ndarray
    y: np.ndarray
    mass: float | None = None  # kg, as entered in Tracker


@dataclass(frozen=True)
class TrackerProject:
    """What physbench reads from a Tracker project (see the module docstring)."""

    source: str
    origin: tuple[float, float]  # Tracker image px
    angle: float  # degrees
    scale: tuple[float, float]  # image px per length unit
    unit: str
    metres_per_unit: float
    start_frame: int
    start_time: float  # ms
    frame_ms: float  # ms
    image_size: tuple[int, int] | None  # (W, H) px
    video: str | None  # the video's path as the project names it
    marks: Mapping[str, Marks]
    filters: tuple[str, ...] = ()
    notes: tuple[str, ...] = field(default_factory=tuple)

    # ----------------------------------------------------------------- the maps

    def _world_to_tracker(self) -> np.ndarray:
        """3 x 3: Tracker world ``(x, y, 1)`` (length units) -> Tracker image ``(X, Y, 1)``."""
        a = math.radians(self.angle)
        c, s = math.cos(a), math.sin(a)
        sx, sy = self.scale
        x0, y0 = self.origin
        return np.array([[sx * c, -sx * s, x0], [-sy * s, -sy * c, y0], [0.0, 0.0, 1.0]])

    def homography(self) -> np.ndarray:
        """3 x 3: physbench pixel ``(u, v, 1)`` -> scene metres ``(x, y, 1)``; refused when a
        video filter moved the pixels."""
        if self.filters:
            raise TrackerFileError(
                f"{self.source}: the video has Tracker filter(s) {', '.join(self.filters)}, which "
                "move its pixels: Tracker's coordinates are of the filtered picture, not of the "
                "video; remove the filter in Tracker and calibrate again, or calibrate with "
                "points (a [[points]] TOML or a u,v,x,y CSV)"
            )
        to_world = np.linalg.inv(self._world_to_tracker())
        shift = np.array([[1.0, 0.0, PIXEL_OFFSET], [0.0, 1.0, PIXEL_OFFSET], [0.0, 0.0, 1.0]])
        metres = np.diag([self.metres_per_unit, self.metres_per_unit, 1.0])
        return metres @ to_world @ shift

    def to_scene(self, xy_tracker: np.ndarray) -> np.ndarray:
        """Scene metres ``(..., 2)`` of Tracker image points ``(..., 2)`` (filters or not: the
        marks and the coordinate system share Tracker's picture)."""
        p = np.asarray(xy_tracker, dtype=float)
        to_world = np.linalg.inv(self._world_to_tracker())
        q = p @ to_world[:2, :2].T + to_world[:2, 2]
        return q * self.metres_per_unit

    def frame_time(self, frames: np.ndarray) -> np.ndarray:
        """Tracker's time (s) of frame numbers ``frames``."""
        n = np.asarray(frames, dtype=float)
        return (self.start_time + (n - self.start_frame) * self.frame_ms) / 1000.0

    @property
    def t0(self) -> float:
        """Tracker's time (s) of the first marked frame: physbench's time 0."""
        first = min(int(m.frames[0]) for m in self.marks.values())
        return float(self.frame_time(np.array([first]))[0])

    def pixels(self) -> dict[str, np.ndarray]:
        """Per track, ``(n, 3)``: recording time (s), and the marks in physbench pixels."""
        return {
            name: np.column_stack(
                [
                    self.frame_time(m.frames) - self.t0,
                    m.x - PIXEL_OFFSET,
                    m.y - PIXEL_OFFSET,
                ]
            )
            for name, m in self.marks.items()
        }

    def recording(self) -> Recording:
        """The hand marks as a :class:`~physbench.recording.Recording` (metres, s from the first
        marked frame), stating an accuracy of :data:`MARK_ACCURACY_PX` in metres."""
        from physbench.recording import Recording, RecordingError, Track

        if not self.marks:
            raise TrackerFileError(
                f"{self.source}: no point-mass track with marks; mark the bodies in Tracker "
                "(Track > New > Point Mass) and save the project"
            )
        tracks = {}
        for name, m in self.marks.items():
            xy = self.to_scene(np.column_stack([m.x, m.y]))
            try:
                tracks[name] = Track(self.frame_time(m.frames) - self.t0, xy[:, 0], xy[:, 1])
            except RecordingError as exc:
                raise TrackerFileError(f"{self.source}: track {name!r}: {exc}") from None
        per_px = self.metres_per_unit / math.sqrt(abs(self.scale[0] * self.scale[1]))
        return Recording(
            tracks,
            fields=("x", "y"),
            source=self.source,
            meta={"tracker_t0": self.t0, "notes": list(self.notes)},
            accuracy=MARK_ACCURACY_PX * per_px,
        )


# --------------------------------------------------------------------------- XML


class _Xml:
    """Reading Tracker's ``XMLControl`` elements, with errors that name the file."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, what: str) -> TrackerFileError:
        return TrackerFileError(f"{self.source}: {what}")

    @staticmethod
    def props(obj: ElementTree.Element) -> dict[str, ElementTree.Element]:
        """The ``<property>`` children of an ``<object>`` by name (the first of each)."""
        out: dict[str, ElementTree.Element] = {}
        for p in obj.findall("property"):
            out.setdefault(p.get("name", ""), p)
        return out

    def number(self, obj: ElementTree.Element, name: str, default: float | None = None) -> float:
        p = self.props(obj).get(name)
        if p is None or p.text is None:
            if default is not None:
                return default
            raise self.fail(f"{obj.get('class', 'object')} has no {name!r}")
        try:
            v = float(p.text)
        except ValueError:
            raise self.fail(f"{name} = {p.text!r} is not a number") from None
        if not math.isfinite(v):
            raise self.fail(f"{name} = {p.text!r} is not a finite number")
        return v

    def text(self, obj: ElementTree.Element, name: str) -> str | None:
        p = self.props(obj).get(name)
        return None if p is None or p.text is None else p.text.strip()

    def child(self, obj: ElementTree.Element, name: str) -> ElementTree.Element | None:
        """The ``<object>`` a property of type object holds."""
        p = self.props(obj).get(name)
        return None if p is None else p.find("object")

    def indexed(self, obj: ElementTree.Element, name: str) -> dict[int, ElementTree.Element]:
        """The objects of an array property (``[n]`` -> its object)."""
        p = self.props(obj).get(name)
        out: dict[int, ElementTree.Element] = {}
        if p is None:
            return out
        for item in p.findall("property"):
            label = item.get("name", "")
            o = item.find("object")
            if o is None or not (label.startswith("[") and label.endswith("]")):
                continue
            try:
                out[int(label[1:-1])] = o
            except ValueError:
                raise self.fail(f"{name}: element {label!r} is not [index]") from None
        return out


def _coords(x: _Xml, root: ElementTree.Element) -> tuple[tuple[float, float], float, tuple]:
    """Origin, angle (degrees) and scale of the project's fixed coordinate system."""
    coords = x.child(root, "coords")
    if coords is None:
        raise x.fail("no coordinate system ('coords'); is this a Tracker project?")
    frames = x.indexed(coords, "framedata")
    if not frames:
        raise x.fail("the coordinate system holds no frame data")
    values = {
        n: tuple(x.number(o, k) for k in ("xorigin", "yorigin", "angle", "xscale", "yscale"))
        for n, o in frames.items()
    }
    first = values[min(values)]
    moved = [n for n, v in values.items() if not np.allclose(v, first, rtol=1e-9, atol=1e-9)]
    if moved:
        raise x.fail(
            f"the coordinate system changes at frame {min(moved)} (origin, angle or scale "
            "differ from frame to frame); physbench needs one calibration for a fixed camera: "
            "in Tracker, fix the origin, angle and scale of the axes"
        )
    x0, y0, angle, sx, sy = first
    if sx == 0 or sy == 0:
        raise x.fail(f"scale ({sx:g}, {sy:g}) px per unit: expected non-zero scales")
    return (x0, y0), angle, (sx, sy)


def _clock(x: _Xml, root: ElementTree.Element) -> tuple[int, float, float, str | None]:
    """Start frame, start time (ms), frame duration (ms) and the video's path."""
    clip = x.child(root, "videoclip")
    control = x.child(root, "clipcontrol")
    if clip is None or control is None:
        raise x.fail("no video clip or clip control: the frame times are unknown")
    start = int(x.number(clip, "startframe", 0.0)) - int(x.number(clip, "frameshift", 0.0))
    t0 = x.number(clip, "starttime", 0.0)
    dt = x.number(control, "delta_t")
    if dt <= 0:
        raise x.fail(f"delta_t = {dt:g} ms: expected a frame duration > 0")
    video = x.child(clip, "video")
    path = None if video is None else x.text(video, "path")
    return start, t0, dt, path


def _filters(root: ElementTree.Element) -> tuple[str, ...]:
    found = set()
    for obj in root.iter("object"):
        name = obj.get("class", "").rsplit(".", 1)[-1]
        if name in GEOMETRIC_FILTERS:
            found.add(name)
    return tuple(sorted(found))


def _marks(
    x: _Xml, root: ElementTree.Element, kg_per_unit: float
) -> tuple[dict[str, Marks], list[str]]:
    """The point-mass tracks and centres of mass, and a note for each centre left out."""
    tracks = x.props(root).get("tracks")
    out: dict[str, Marks] = {}
    left: list[str] = []
    if tracks is None:
        return out, left
    for item in tracks.findall("property"):
        obj = item.find("object")
        if obj is None or obj.get("class") != _POINT_MASS:
            continue
        name = (x.text(obj, "name") or "").strip()
        if not name:
            raise x.fail("a point-mass track has no name; name it in Tracker")
        if name in out:
            raise x.fail(f"two point-mass tracks are named {name!r}; rename one in Tracker")
        steps = x.indexed(obj, "framedata")
        if not steps:
            continue
        frames = np.array(sorted(steps))
        xs = np.array([x.number(steps[n], "x") for n in frames])
        ys = np.array([x.number(steps[n], "y") for n in frames])
        mass = x.number(obj, "mass", math.nan)
        out[name] = Marks(frames, xs, ys, None if math.isnan(mass) else mass * kg_per_unit)
    for item in tracks.findall("property"):
        obj = item.find("object")
        if obj is not None and obj.get("class") == _CENTRE_OF_MASS:
            name, centre = _centre_of_mass(x, obj, out, kg_per_unit)
            if isinstance(centre, Marks):
                out[name] = centre
            else:
                left.append(f"centre of mass {name!r} left out: {centre}")
    return out, left


def _centre_of_mass(
    x: _Xml, obj: ElementTree.Element, points: Mapping[str, Marks], kg_per_unit: float
) -> tuple[str, Marks | str]:
    """A ``CenterOfMass`` track's name and :class:`Marks`: the mass-weighted mean of the point
    masses it names, in the frames where all are marked; or, as Tracker shows no point for it,
    why not (it names no point mass of the file, or they share no marked frame)."""
    name = (x.text(obj, "name") or "").strip()
    if not name:
        raise x.fail("a centre-of-mass track has no name; name it in Tracker")
    if name in points:
        raise x.fail(f"two tracks are named {name!r}; rename one in Tracker")
    listed = x.props(obj).get("masses")
    members = [] if listed is None else [(p.text or "").strip() for p in listed.findall("property")]
    missing = [m for m in members if m not in points]
    if not members or missing:
        named = ", ".join(map(repr, missing)) if missing else "no point mass"
        return name, f"it names {named}, not a marked point mass of the file"
    frames = points[members[0]].frames
    for m in members[1:]:
        frames = np.intersect1d(frames, points[m].frames)
    if not len(frames):
        return name, f"its point masses {', '.join(map(repr, members))} share no marked frame"
    unstated = DEFAULT_MASS * kg_per_unit
    weights = [unstated if points[m].mass is None else points[m].mass for m in members]
    total = float(sum(weights))
    if not total > 0:
        raise x.fail(f"centre of mass {name!r}: its point masses weigh {total:g} in all")
    xs, ys = np.zeros(len(frames)), np.zeros(len(frames))
    for m, w in zip(members, weights, strict=True):
        at = np.searchsorted(points[m].frames, frames)
        xs += w * points[m].x[at]
        ys += w * points[m].y[at]
    return name, Marks(frames, xs / total, ys / total, total)


def _unit(x: _Xml, root: ElementTree.Element, key: str, table: Mapping[str, float]) -> tuple:
    """``(unit, factor, note)`` of ``length_unit`` or ``mass_unit`` (absent: the SI unit)."""
    unit = x.text(root, key)
    si = next(iter(table)) if key == "mass_unit" else "m"
    if unit is None or unit == "":
        return si, 1.0, f"{key} not stated: taken as {si}"
    if unit not in table:
        raise x.fail(f"{key} = {unit!r}: physbench knows {', '.join(table)}")
    return unit, table[unit], None


def parse_tracker_xml(text: str | bytes, *, source: str = "<trk>") -> TrackerProject:
    """A :class:`TrackerProject` from the XML of a ``.trk`` file."""
    x = _Xml(source)
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise x.fail(f"not readable as XML ({exc})") from None
    cls = root.get("class", "")
    if root.tag != "object" or not cls.endswith("TrackerPanel"):
        raise x.fail(
            f"the root element is <{root.tag} class={cls!r}>; a Tracker project's is a "
            "TrackerPanel object (save it from Tracker as a .trk or .trz)"
        )
    origin, angle, scale = _coords(x, root)
    unit, metres, note = _unit(x, root, "length_unit", LENGTH_UNITS)
    _, kg, mass_note = _unit(x, root, "mass_unit", MASS_UNITS)
    start, t0, dt, video = _clock(x, root)
    marks, left = _marks(x, root, kg)
    w, h = x.number(root, "width", 0.0), x.number(root, "height", 0.0)
    return TrackerProject(
        source=source,
        origin=origin,
        angle=angle,
        scale=scale,
        unit=unit,
        metres_per_unit=metres,
        start_frame=start,
        start_time=t0,
        frame_ms=dt,
        image_size=(round(w), round(h)) if w > 0 and h > 0 else None,
        video=video,
        marks=marks,
        filters=_filters(root),
        notes=tuple(n for n in (note, mass_note, *left) if n),
    )


def tracker_path(path: str | Path) -> tuple[Path, str | None]:
    """The file of a Tracker project path and the project it names inside an archive:
    ``ARCHIVE.trz:INNER.trk`` (as physbench names a project's source) is ``(ARCHIVE.trz,
    INNER.trk)``; any other path is itself, with no member."""
    text = str(path)
    at = text.lower().rfind(".trz:")
    if at < 0:
        return Path(text), None
    return Path(text[: at + 4]), text[at + 5 :] or None


def is_tracker_file(path: str | Path) -> bool:
    return tracker_path(path)[0].suffix.lower() in TRACKER_SUFFIXES


def read_tracker_project(path: str | Path, *, member: str | None = None) -> TrackerProject:
    """Read a ``.trk`` file, or the ``.trk`` inside a ``.trz`` archive: ``member`` (or a path
    ``ARCHIVE.trz:MEMBER``) names it, by its path in the archive or its file name, when the
    archive holds several."""
    p, named = tracker_path(path)
    member = member or named
    if not p.is_file():
        raise TrackerFileError(f"Tracker project {str(p)!r} does not exist")
    if p.suffix.lower() == ".trk":
        if p.stat().st_size > MAX_TRK_BYTES:
            raise TrackerFileError(f"{p}: over {MAX_TRK_BYTES >> 20} MiB; not a Tracker project?")
        return _said(parse_tracker_xml(p.read_bytes(), source=str(p)))
    if p.suffix.lower() != ".trz":
        raise TrackerFileError(f"{p}: expected a Tracker project (.trz or .trk)")
    try:
        with zipfile.ZipFile(p) as z:
            every = [i for i in z.infolist() if i.filename.lower().endswith(".trk")]
            projects = every if member is None else _named(every, member)
            if len(projects) != 1:
                raise _which(p, every, member)
            info = projects[0]
            if info.file_size > MAX_TRK_BYTES:
                raise TrackerFileError(f"{p}: {info.filename} is over {MAX_TRK_BYTES >> 20} MiB")
            data = z.read(info)
    except zipfile.BadZipFile:
        raise TrackerFileError(
            f"{p}: not a zip archive; a .trz is a zipped Tracker project"
        ) from None
    return _said(parse_tracker_xml(data, source=f"{p}:{info.filename}"))


def _said(project: TrackerProject) -> TrackerProject:
    """``project``, its notes (a unit taken as SI, a centre of mass left out) each warned of."""
    import warnings

    from physbench.errors import PhysbenchWarning

    for note in project.notes:
        warnings.warn(PhysbenchWarning(f"{project.source}: {note}"), stacklevel=3)
    return project


def _named(projects: list[zipfile.ZipInfo], member: str) -> list[zipfile.ZipInfo]:
    """The archive's projects ``member`` names: by its path in the archive, else its file name."""
    exact = [i for i in projects if i.filename == member]
    return exact or [i for i in projects if posixpath.basename(i.filename) == member]


def _which(p: Path, projects: list[zipfile.ZipInfo], member: str | None) -> TrackerFileError:
    """The error for an archive whose project is not named, or not found, by ``member``."""
    names = ", ".join(repr(i.filename) for i in projects) or "none"
    if not projects:
        return TrackerFileError(f"{p}: holds no Tracker project (.trk); expected one")
    if member is not None:
        return TrackerFileError(f"{p}: no project {member!r} in it; it holds {names}")
    example = posixpath.basename(projects[0].filename)
    return TrackerFileError(
        f"{p}: holds {len(projects)} Tracker projects ({names}); name one after a colon, "
        f"as in '{p}:{example}'"
    )


# --------------------------------------------------------------------------- the video

_NUMBERED = re.compile(r"^(?P<stem>.*?)(?P<number>\d+)(?P<suffix>\.[A-Za-z]+)$")


def _sequence(names: list[str], first: str) -> list[str]:
    """The names of the image sequence that ``first`` begins (same folder, stem and suffix,
    numbered from ``first``'s number on), in number order; ``[first]`` if it is not numbered."""
    folder, base = posixpath.split(first)
    m = _NUMBERED.match(base)
    if m is None:
        return [first]
    found = []
    for name in names:
        f, b = posixpath.split(name)
        n = _NUMBERED.match(b)
        same = n is not None and (n["stem"], n["suffix"]) == (m["stem"], m["suffix"])
        if f == folder and same and int(n["number"]) >= int(m["number"]):
            found.append((int(n["number"]), name))
    return [name for _, name in sorted(found)]


def project_video(
    path: str | Path, into: str | Path, project: TrackerProject | None = None
) -> Path:
    """Where physbench can read the video of the Tracker project at ``path``: a file, or for an
    image sequence a folder holding its images alone (numbered in order). From a ``.trz`` the
    video is extracted into the folder ``into``; beside a ``.trk`` it is read where the project
    names it (relative to the project's folder), a sequence's images copied into ``into``.
    Raises :class:`TrackerFileError` naming what is missing."""
    from physbench.codec import IMAGE_SUFFIXES

    project = project or read_tracker_project(path)
    p, into = tracker_path(path)[0], Path(into)
    if not project.video:
        raise TrackerFileError(f"{p}: the project names no video; give the video itself")
    name = project.video.replace("\\", "/")
    sequence = posixpath.splitext(name)[1].lower() in IMAGE_SUFFIXES  # a folder's images
    if p.suffix.lower() == ".trk":
        target = Path(name) if Path(name).is_absolute() else p.parent / name
        if not target.is_file():
            raise TrackerFileError(
                f"{p}: its video {project.video!r} is not at {str(target)!r}; give the video "
                "itself, with the project as --calibration"
            )
        if not sequence:
            return target
        names = [f.as_posix() for f in target.parent.iterdir()]
        return _gather(
            into, _sequence(names, target.as_posix()), lambda n, dst: shutil.copy(n, dst)
        )
    member = project.source.removeprefix(f"{p}:")
    wanted = posixpath.normpath(posixpath.join(posixpath.dirname(member), name))
    with zipfile.ZipFile(p) as z:
        names = z.namelist()
        if wanted not in names:
            same = [n for n in names if posixpath.basename(n) == posixpath.basename(wanted)]
            if len(same) != 1:
                raise TrackerFileError(
                    f"{p}: its video {project.video!r} is not in the archive; give the video "
                    "itself, with the project as --calibration"
                )
            wanted = same[0]
        if not sequence:
            into.mkdir(parents=True, exist_ok=True)
            target = into / posixpath.basename(wanted)
            with z.open(wanted) as src, target.open("wb") as dst:
                shutil.copyfileobj(src, dst)
            return target

        def extract(n: str, dst: Path) -> None:
            with z.open(n) as src, dst.open("wb") as out:
                shutil.copyfileobj(src, out)

        return _gather(into, _sequence(names, wanted), extract)


def _gather(into: Path, names: list[str], put: Callable[[str, Path], object]) -> Path:
    """A folder in ``into`` holding the images ``names`` in their order (renumbered)."""
    folder = into / "frames"
    folder.mkdir(parents=True, exist_ok=True)
    width = len(str(len(names)))
    for k, n in enumerate(names):
        put(n, folder / f"{k:0{width}d}{posixpath.splitext(n)[1].lower()}")
    return folder
