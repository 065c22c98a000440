"""How a tracking went, for a person and for the commands: :class:`TrackSummary`.

Per body: the frames it was seen in and in view, the spans of frames where it was in view but not
found ("lost from 0.40 to 0.60 s", never a count of gaps) or out of view, the detections rejected
for not looking like it, the frames left out at collisions, a disc's frames measured by their
centroid, and the accuracy its track states. A body lost in more than :data:`LOST_SHARE` of the
frames where it was in view is a failure (:meth:`TrackSummary.failures`), which the tracking
commands report and exit on.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from physbench.errors import counted

#: A body unseen in more than this share of the frames where it was in view fails the tracking
#: (:class:`~physbench.video.track.TrackLostError`; ``allow_gaps`` keeps the recording with its
#: gaps).
LOST_SHARE = 0.1


@dataclass
class Spans:
    """Runs of consecutive frames in one condition (unseen, out of view) as ``(first, last)``
    frame times, and how many frames."""

    spans: list[tuple[float, float]] = field(default_factory=list)
    frames: int = 0
    open: bool = False

    def mark(self, t: float) -> None:
        if self.open:
            self.spans[-1] = (self.spans[-1][0], t)
        else:
            self.spans.append((t, t))
        self.open = True
        self.frames += 1

    def close(self) -> None:
        self.open = False


@dataclass(frozen=True)
class TrackSummary:
    """How tracking went: ``frames`` read over ``duration`` s; per body the ``detections``
    (frames with a measurement), the frames where it was ``in_view``, the spans ``(first, last)``
    (s) of frames where it was in view but ``lost``, and those where it was ``out_of_view``; the
    calibration's reprojection error (px), the processing speed (frames/s), the samples left out
    at collisions (``contacts``), the detections ``rejected`` for not looking like the body,
    each track's stated accuracy (px, ``accuracy_px``), a disc's frames measured by their
    ``centroids`` for want of an outline, and a turning body's stated ``angle_accuracy`` (rad)."""

    frames: int
    duration: float
    detections: dict[str, int]
    in_view: dict[str, int]
    lost: dict[str, list[tuple[float, float]]]
    reprojection_error: float
    fps: float = 0.0
    #: Per body, the samples left out because their exposure spans a collision
    #: (:mod:`physbench.video.contacts`).
    contacts: dict[str, int] = field(default_factory=dict)
    out_of_view: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    rejected: dict[str, int] = field(default_factory=dict)
    accuracy_px: dict[str, float] = field(default_factory=dict)
    #: Per disc, the frames measured by their centroid (no outline could be fitted).
    centroids: dict[str, int] = field(default_factory=dict)
    angle_accuracy: dict[str, float] = field(default_factory=dict)
    #: The spans ``(first, last)`` (s) of frames whose picture lay half a pixel or more off the
    #: background's (:mod:`~physbench.video.steadiness`), and the largest such shift (px).
    camera_moved: list[tuple[float, float]] = field(default_factory=list)
    camera_shift_px: float = 0.0
    #: The bodies the clip's median background held where they stayed put, tracked against it
    #: mended there (:mod:`~physbench.video.held`).
    held: list[str] = field(default_factory=list)

    def camera_words(self) -> str:
        """``the camera moved by up to 2.5 px against the background, from 0.20 to 0.90 s``, or
        ``""`` where it stayed put."""
        if not self.camera_moved:
            return ""
        return (
            f"the camera moved by up to {self.camera_shift_px:.1f} px against the background, "
            f"{lost_words(self.camera_moved)}"
        )

    def unseen(self, body: str) -> int:
        """Frames where ``body`` was in view but not found."""
        return self.in_view.get(body, 0) - self.detections.get(body, 0)

    def lost_bodies(self, share: float = LOST_SHARE) -> list[str]:
        """The bodies unseen in more than ``share`` of the frames where they were in view."""
        return [
            name
            for name in self.detections
            if self.in_view.get(name, 0) and self.unseen(name) > share * self.in_view[name]
        ]

    def failures(self, share: float = LOST_SHARE) -> list[str]:
        """One sentence per body of :meth:`lost_bodies`."""
        out = []
        for name in self.lost_bodies(share):
            n, unseen = self.in_view[name], self.unseen(name)
            out.append(
                f"body {name!r} was lost in {unseen} of the {n} frames where it was in view "
                f"({unseen / n:.0%}, more than {share:.0%}): lost "
                f"{lost_words(self.lost.get(name, []))}"
            )
        return out

    def format(self) -> str:
        """A few lines for a person."""
        lines = [
            f"tracked {counted(len(self.detections), 'body')} over "
            f"{counted(self.frames, 'frame')} "
            f"({self.duration:.2f} s) at {self.fps:.0f} frames/s; calibration reprojection "
            f"error {self.reprojection_error:.2f} px"
        ]
        for name, n in self.detections.items():
            view = self.in_view.get(name, self.frames)
            where = "" if view == self.frames else " in view"
            parts = [f"seen in {n}/{view} frames{where}"]
            if self.lost.get(name):
                parts.append(f"lost {lost_words(self.lost[name])}")
            if self.out_of_view.get(name):
                parts.append(f"out of view {lost_words(self.out_of_view[name])}")
            if self.rejected.get(name):
                parts.append(
                    f"{counted(self.rejected[name], 'detection')} rejected (not its size or colour)"
                )
            if self.centroids.get(name):
                parts.append(
                    f"{counted(self.centroids[name], 'frame')} by the centroid (no outline fitted)"
                )
            if self.contacts.get(name):
                parts.append(
                    f"{counted(self.contacts[name], 'collision frame')} left out (the exposure "
                    "spans the collision)"
                )
            if name in self.accuracy_px:
                parts.append(f"accuracy {self.accuracy_px[name]:.2f} px")
            if name in self.angle_accuracy:
                parts.append(f"angles to {1e3 * self.angle_accuracy[name]:.1f} mrad")
            lines.append(f"  {name:>8}: " + "; ".join(parts))
        if self.camera_moved:
            lines.append(f"  {self.camera_words()}")
        if self.held:
            lines.append(
                f"  the clip's median held {', '.join(self.held)} where they stayed put: tracked "
                "against it mended from the frames where they were elsewhere"
            )
        return "\n".join(lines)


def lost_words(spans: list[tuple[float, float]]) -> str:
    """``from 0.33 to 3.33 s, at 4.00 s``."""
    words = []
    for a, b in spans:
        words.append(f"at {a:.2f} s" if b - a < 1e-9 else f"from {a:.2f} to {b:.2f} s")
    return ", ".join(words)
