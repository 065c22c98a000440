"""``physbench scene new``: write the scene TOML of one's own setup (a ball in flight, a ball on a
surface, a pendulum or a puck) from a few answers, estimating the initial state from a recording's
first samples (:mod:`physbench.scenes.setups`)."""

from __future__ import annotations

import argparse

from physbench import numeric
from physbench.commands.arguments import add_quiet_argument, positive_int

KINDS_HELP = (
    "flight (a ball thrown or dropped, side view), surface (a ball rolling or sliding along a "
    "level surface or a ramp, side view), pendulum (a bob on a rod or string), puck (a disc "
    "sliding on a table seen from above)"
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.description = (
        "Write the scene TOML of your own setup from a few answers. What is not given is "
        "estimated from --from (a recording CSV or a Tracker project): the initial position and "
        "velocity from its first 0.3 s, a pendulum's pivot from the circle through its samples, "
        "the frame rate and length from its samples."
    )
    p.add_argument("action", choices=("new",), help="new: write a new scene file")
    p.add_argument("kind", choices=("flight", "surface", "pendulum", "puck"), help=KINDS_HELP)
    p.add_argument("--out", required=True, metavar="FILE", help="write the scene TOML here")
    p.add_argument(
        "--radius", type=numeric.POSITIVE, required=True, metavar="M", help="body radius (m)"
    )
    p.add_argument("--body", help="body name (default: the recording's track, else ball/bob/puck)")
    p.add_argument("--mass", type=numeric.POSITIVE, metavar="KG", help="body mass (default 1 kg)")
    p.add_argument("--name", help="scene name (default my_KIND)")
    src = p.add_argument_group("from measurements")
    src.add_argument(
        "--from",
        dest="source",
        metavar="REC",
        help="a recording (.csv) or Tracker project (.trz, .trk) to estimate the rest from",
    )
    src.add_argument(
        "--video",
        metavar="CLIP",
        help="the clip: its frame rate and length (and with --calibration, its view as bounds)",
    )
    src.add_argument("--calibration", metavar="CAL", help="calibration file (for --pixel, --video)")
    st = p.add_argument_group("answers (each overrides its estimate)")
    st.add_argument("--fps", type=numeric.POSITIVE, help="frames per second")
    st.add_argument("--frames", type=positive_int, help="frames to simulate")
    st.add_argument("--position", type=numeric.ANY, nargs=2, metavar=("X", "Y"), help="start (m)")
    st.add_argument(
        "--pixel",
        type=numeric.ANY,
        nargs=2,
        action="append",
        metavar=("U", "V"),
        help="the body's centre pixel in the first frame (needs --calibration); given again for "
        "the next frames, it gives the velocity too",
    )
    st.add_argument("--velocity", type=numeric.ANY, nargs=2, metavar=("VX", "VY"), help="m/s")
    st.add_argument(
        "--pivot", type=numeric.ANY, nargs=2, metavar=("X", "Y"), help="pendulum pivot (m)"
    )
    st.add_argument(
        "--surface-angle",
        type=numeric.ANY,
        default=0.0,
        metavar="DEG",
        help="surface: its angle from the +x axis, counter-clockwise (default 0: level)",
    )
    st.add_argument(
        "--bounds", type=numeric.ANY, nargs=4, metavar=("XMIN", "YMIN", "XMAX", "YMAX"), help="m"
    )
    add_quiet_argument(p, "print only the file written")


def main(args: argparse.Namespace) -> int:
    from pathlib import Path

    import numpy as np

    from physbench.commands.console import wrote
    from physbench.errors import PhysbenchError
    from physbench.scenes.setups import Answers, build_setup, format_setup, start_from_points

    recording, mass, notes = None, args.mass, []
    if args.source:
        recording, tracker_mass = _recording(args.source, args.body)
        if mass is None and tracker_mass is not None:
            mass = tracker_mass
            notes.append(f"mass {mass:g} kg from the Tracker project")
    cal = None
    if args.calibration:
        from physbench.calibration import load_calibration

        cal = load_calibration(args.calibration)
    fps, frames, bounds = args.fps, args.frames, args.bounds
    if args.video:
        from physbench.video.reader import VideoReader

        if Path(args.video).is_dir() and not args.fps:
            raise PhysbenchError(
                f"--video {args.video!r} is a folder of images, which carry no frame rate: "
                "give it with --fps"
            )
        info = VideoReader(args.video, fps=args.fps).info()
        fps = fps or info.rate or None
        if frames is None and info.frames:
            frames = info.frames
        elif frames is None and info.duration and fps:
            frames = round(info.duration * fps)
        if bounds is None and cal is not None:
            w, h = info.width, info.height
            corners = cal.to_scene(
                np.array([[-0.5, -0.5], [w - 0.5, -0.5], [w - 0.5, h - 0.5], [-0.5, h - 0.5]])
            )
            bounds = [*corners.min(axis=0), *corners.max(axis=0)]
    position, velocity = args.position, args.velocity
    if args.pixel is not None:
        if cal is None:
            raise PhysbenchError("--pixel needs --calibration (to turn the pixel into metres)")
        if position is not None:
            raise PhysbenchError("give the start once: --position or --pixel")
        points = cal.to_scene(np.asarray(args.pixel, dtype=float))
        if len(points) > 1 and not fps:
            raise PhysbenchError("--pixel in several frames needs the frame rate: --fps or --video")
        start = start_from_points(args.kind, points, fps or 1.0)
        position = start.position
        if len(points) > 1 and velocity is None:
            velocity = start.velocity
            notes.append(f"velocity from the body's pixels in the first {len(points)} frames")
    answers = Answers(
        kind=args.kind,
        radius=args.radius,
        body=args.body,
        mass=mass,
        fps=fps,
        frames=frames,
        position=None if position is None else tuple(position),
        velocity=None if velocity is None else tuple(velocity),
        pivot=None if args.pivot is None else tuple(args.pivot),
        surface_angle=args.surface_angle,
        bounds=None if bounds is None else tuple(bounds),
        name=args.name,
    )
    scene, more = build_setup(answers, recording)
    text = format_setup(scene, [*notes, *more])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(text, encoding="utf-8")
    if not args.quiet:
        for line in [*notes, *more]:
            print(line)
    wrote(args.out, args)
    return 0


def _recording(path: str, body: str | None) -> tuple:
    """The recording of ``path`` (CSV or Tracker project) and the Tracker mass of ``body`` (or
    of its one track)."""
    from physbench.recording import read_recording
    from physbench.tracker_files import is_tracker_file, read_tracker_project

    if not is_tracker_file(path):
        return read_recording(path), None
    project = read_tracker_project(path)
    rec = project.recording()
    name = body or (rec.bodies[0] if len(rec.bodies) == 1 else None)
    marks = project.marks.get(name) if name else None
    return rec, None if marks is None else marks.mass
