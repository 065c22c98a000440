"""``physbench track``: follow a scene's bodies through a video into a recording CSV."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from physbench.commands.arguments import (
    add_quiet_argument,
    add_scene_argument,
    add_video_input_arguments,
    seed_int,
)

if TYPE_CHECKING:
    from physbench.scene import Scene


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "video",
        metavar="VIDEO",
        help="a video file (mp4, mov, avi, mkv, webm, gif, ...), a folder of images, or a "
        "Tracker project (.trz, .trk): its video from its first marked frame, with its "
        "calibration",
    )
    add_scene_argument(
        p,
        required=True,
        help="the filmed scene (its initial positions say where the bodies start)",
    )
    p.add_argument("--seed", type=seed_int, default=0, help="scene instance seed (default 0)")
    p.add_argument("--out", required=True, metavar="REC.csv", help="write the recording here")
    p.add_argument(
        "--pixels-out",
        metavar="PX.csv",
        help="where to write the measured pixel centres (t, body, u, v; default: beside --out "
        "as REC.pixels.csv)",
    )
    p.add_argument(
        "--preview", metavar="FILE.mp4|.gif", help="write the video with the tracks drawn on"
    )
    add_video_input_arguments(p)
    add_quiet_argument(p, "no output but errors and warnings")


def main(args: argparse.Namespace) -> int:
    import tempfile

    from physbench.calibration import load_calibration
    from physbench.commands.console import show_progress, wrote
    from physbench.errors import PhysbenchError
    from physbench.recording import write_recordings
    from physbench.scenes import resolve_scene
    from physbench.video.overlay import OVERLAY_SUFFIXES, write_overlay
    from physbench.video.track import TrackLostError, track_video

    video = Path(args.video)
    for flag, value in (("--out", args.out), ("--preview", args.preview)):
        if value and video.exists() and Path(value).resolve() == video.resolve():
            raise PhysbenchError(f"{flag} {value!r} is the input video; choose another file")
    if Path(args.out).suffix.lower() != ".csv":
        raise PhysbenchError(f"--out {args.out!r}: expected a .csv recording file")
    if args.pixels_out and Path(args.pixels_out).resolve() in (
        Path(args.out).resolve(),
        video.resolve(),
    ):
        raise PhysbenchError(f"--pixels-out {args.pixels_out!r} is another output or the input")
    if args.preview and Path(args.preview).suffix.lower() not in OVERLAY_SUFFIXES:
        raise PhysbenchError(
            f"--preview {args.preview!r}: expected a {' or '.join(OVERLAY_SUFFIXES)} file"
        )
    scene = resolve_scene(args.scene, args.seed).validate()
    with tempfile.TemporaryDirectory(prefix="physbench-track-") as tmp:
        src = _source(args, video, scene, Path(tmp))
        if src.note and not args.quiet:
            print(src.note)
        calibration = load_calibration(src.calibration) if src.calibration else None

        def preview(pixels: dict) -> None:
            write_overlay(
                args.preview,
                src.clip,
                pixels,
                start=src.start,
                end=args.end,
                fps=scene.fps,
                capture_fps=src.capture_fps,
            )
            wrote(args.preview, args)

        try:
            result = track_video(
                src.clip,
                scene,
                calibration,
                start=src.start,
                end=args.end,
                background=args.background,
                allow_gaps=args.allow_gaps,
                progress=show_progress(args),
                transfer=args.transfer,
                capture_fps=src.capture_fps,
            )
        except TrackLostError as exc:
            # A failure: no recording; the summary and a preview, if asked, show what was lost.
            if not args.quiet:
                print(exc.result.summary.format())
            if args.preview:
                preview(exc.result.pixels)
            raise
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        write_recordings(args.out, result.recording)
        pixels_out = args.pixels_out or str(Path(args.out).with_suffix(".pixels.csv"))
        write_pixels(pixels_out, result.pixels)
        if not args.quiet:
            print(result.summary.format())
        wrote(args.out, args)
        wrote(pixels_out, args)
        if args.preview:
            preview(result.pixels)
    return 0


@dataclass(frozen=True)
class _Source:
    """What ``track`` reads: the clip, where it starts, its capture rate and calibration, and a
    line that says where they came from (a Tracker project's)."""

    clip: Path
    start: float | None
    capture_fps: float | None
    calibration: str | None
    note: str = ""


def _source(args: argparse.Namespace, video: Path, scene: Scene, tmp: Path) -> _Source:
    """The clip to track: ``video`` itself, or the video a Tracker project names (extracted into
    ``tmp``), from its first marked frame (where ``scene new --from`` starts the scene), with
    the project's calibration and its clock's rate where the file plays at another (slow
    motion), each unless given."""
    from physbench.tracker_files import is_tracker_file, project_video, read_tracker_project
    from physbench.video.reader import VideoReader

    plain = _Source(video, args.start, args.capture_fps, args.calibration)
    if not is_tracker_file(video):
        return plain
    project = read_tracker_project(video)
    clip = project_video(video, tmp, project)
    rate = VideoReader(clip, fps=scene.fps).info().rate
    first = min((int(m.frames[0]) for m in project.marks.values()), default=project.start_frame)
    start = args.start if args.start is not None else max(0.0, (first - 0.5) / rate)
    clock = 1000.0 / project.frame_ms
    capture = args.capture_fps
    if capture is None and not clip.is_dir() and abs(clock / rate - 1) > 0.02:
        capture = clock  # the teacher set Tracker's clock to the rate it was filmed at
    said = [f"{video}: its video {project.video!r}"]
    if args.start is None:
        said.append(f"from frame {first}" + (" (the first marked)" if project.marks else ""))
    if args.calibration is None:
        said.append("calibrated by the project")
    if capture != args.capture_fps:
        said.append(f"filmed at {clock:.4g} frames/s by the project's clock (the file plays at "
                    f"{rate:.4g})")  # fmt: skip
    return _Source(clip, start, capture, args.calibration or str(video), ", ".join(said))


#: The first lines of a pixel-centre file.
PIXELS_HEADER = (
    "# pixel centres the tracker measured (each blob's centre in the image): u right, v down, "
    "pixel centres at integers (the top-left pixel's centre is (0, 0); Tracker's is (0.5, 0.5))\n"
)


def write_pixels(path: str, pixels: dict) -> None:
    """Each body's measured image centres ``(t, u, v)`` as CSV ``t,body,u,v``."""
    import csv
    from pathlib import Path

    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="", encoding="utf-8") as fh:
        fh.write(PIXELS_HEADER)
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["t", "body", "u", "v"])
        for body, tuv in pixels.items():
            for t, u, v in tuv:
                w.writerow([repr(float(t)), body, repr(float(u)), repr(float(v))])
