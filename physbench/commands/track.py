"""``physbench track``: follow a scene's bodies through a video into a recording CSV."""

from __future__ import annotations

import argparse

from physbench.commands.arguments import (
    add_quiet_argument,
    add_scene_argument,
    add_video_input_arguments,
    seed_int,
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "video",
        metavar="VIDEO",
        help="a video file (mp4, mov, avi, mkv, webm, gif, ...) or a folder of images",
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
    from pathlib import Path

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
    calibration = load_calibration(args.calibration) if args.calibration else None
    try:
        result = track_video(
            video,
            scene,
            calibration,
            start=args.start,
            end=args.end,
            background=args.background,
            allow_gaps=args.allow_gaps,
            progress=show_progress(args),
            transfer=args.transfer,
            capture_fps=args.capture_fps,
        )
    except TrackLostError as exc:
        # A failure: no recording; the summary and a preview, if asked, show what was lost.
        if not args.quiet:
            print(exc.result.summary.format())
        if args.preview:
            write_overlay(
                args.preview,
                video,
                exc.result.pixels,
                start=args.start,
                end=args.end,
                fps=scene.fps,
                capture_fps=args.capture_fps,
            )
            wrote(args.preview, args)
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
        write_overlay(
            args.preview,
            video,
            result.pixels,
            start=args.start,
            end=args.end,
            fps=scene.fps,
            capture_fps=args.capture_fps,
        )
        wrote(args.preview, args)
    return 0


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
