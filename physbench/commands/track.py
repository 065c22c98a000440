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
    from physbench.video.track import track_video

    video = Path(args.video)
    for flag, value in (("--out", args.out), ("--preview", args.preview)):
        if value and video.exists() and Path(value).resolve() == video.resolve():
            raise PhysbenchError(f"{flag} {value!r} is the input video; choose another file")
    if Path(args.out).suffix.lower() != ".csv":
        raise PhysbenchError(f"--out {args.out!r}: expected a .csv recording file")
    if args.preview and Path(args.preview).suffix.lower() not in OVERLAY_SUFFIXES:
        raise PhysbenchError(
            f"--preview {args.preview!r}: expected a {' or '.join(OVERLAY_SUFFIXES)} file"
        )
    scene = resolve_scene(args.scene, args.seed).validate()
    calibration = load_calibration(args.calibration) if args.calibration else None
    result = track_video(
        video,
        scene,
        calibration,
        start=args.start,
        end=args.end,
        background=args.background,
        progress=show_progress(args),
    )
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_recordings(args.out, result.recording)
    if not args.quiet:
        print(result.summary.format())
    wrote(args.out, args)
    if args.preview:
        write_overlay(args.preview, video, result.pixels, start=args.start, end=args.end)
        wrote(args.preview, args)
    return 0
