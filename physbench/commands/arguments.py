"""Command-line arguments that several commands share, so that one flag means one thing
everywhere: ``KEY=VALUE`` options and the renderer choice (``--renderer``, ``--renderer-option``,
``--resolution``, ``--render-mode``)."""

from __future__ import annotations

import argparse
import json
from typing import Any

#: Kept here (not imported from physbench.render.base) so building a parser imports nothing heavy.
RENDER_MODES = ("mark", "instance", "mask", "rgb")


def parse_key_values(items: list[str], flag: str) -> dict[str, Any]:
    """``["startup=5", "sampler=cmaes"]`` -> ``{"startup": 5, "sampler": "cmaes"}``: values parse
    as JSON, else stay text. ``flag`` names the option in errors."""
    from physbench.errors import PhysbenchError

    out: dict[str, Any] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise PhysbenchError(f"{flag} {item!r}: expected KEY=VALUE, e.g. {flag} startup=5")
        try:
            value = json.loads(raw)
        except ValueError:
            value = raw
        out[key.strip()] = value
    return out


def add_renderer_choice(
    p: argparse.ArgumentParser,
    *,
    renderer_help: str = "renderer of the frames (default: raster; see `physbench plugins`)",
) -> None:
    """``--renderer NAME`` and ``--renderer-option KEY=VALUE`` (repeatable); read them with
    :func:`renderer_choice`."""
    p.add_argument("--renderer", default=None, metavar="NAME", help=renderer_help)
    p.add_argument(
        "-R",
        "--renderer-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="renderer option, repeatable (values parse as JSON, else text)",
    )


def add_renderer_arguments(
    p: argparse.ArgumentParser, *, resolution: int = 64, from_frames: bool = False
) -> None:
    """:func:`add_renderer_choice` plus ``--resolution PX`` and ``--render-mode MODE``.
    The mode defaults to ``None``: the renderer's first declared layout
    (:func:`~physbench.experiment.default_render_mode`). ``from_frames``: for commands that fit
    observed frames, the resolution defaults to ``None`` too, and both are read from the frames
    (width, channel count)."""
    add_renderer_choice(p)
    p.add_argument(
        "--resolution",
        type=int,
        default=None if from_frames else resolution,
        metavar="PX",
        help="frame width in pixels (default: "
        + ("the frames' width" if from_frames else str(resolution))
        + ")",
    )
    p.add_argument(
        "--render-mode",
        "--mode",
        dest="render_mode",
        default=None,
        choices=RENDER_MODES,
        help="channel layout of the frames (default: "
        + (
            "from the frames' channels: 1 mask, 2 mark, one per body instance"
            if from_frames
            else "the renderer's first layout: mark for raster, rgb for camera"
        )
        + ")",
    )


def renderer_choice(args: argparse.Namespace) -> tuple[str, dict[str, Any]]:
    """The renderer name (the default when not given) and its options from the parsed ``args``."""
    from physbench.render.base import DEFAULT_RENDERER

    return args.renderer or DEFAULT_RENDERER, parse_key_values(
        args.renderer_option, "--renderer-option"
    )


def make_renderer_from(args: argparse.Namespace) -> Any:
    """The renderer the parsed ``args`` choose, built with their resolution and render mode."""
    from physbench.experiment import make_renderer

    name, options = renderer_choice(args)
    return make_renderer(name, options, resolution=args.resolution, mode=args.render_mode)


def add_video_input_arguments(group: argparse._ActionsContainer) -> None:
    """The flags that say how to read a camera's video: ``--calibration``, ``--background``,
    ``--start``, ``--end`` (the same in ``track``, ``run --video`` and ``discover VIDEO``)."""
    group.add_argument(
        "--calibration",
        default=None,
        metavar="C.toml",
        help="pixels to metres (default: the scene's bounds fill the frame; docs/video.md)",
    )
    group.add_argument(
        "--background",
        default=None,
        metavar="IMAGE",
        help="a picture of the empty scene (default: the video's median)",
    )
    group.add_argument(
        "--start", type=float, default=None, metavar="S", help="skip the video's first S seconds"
    )
    group.add_argument(
        "--end", type=float, default=None, metavar="S", help="stop at S seconds into the video"
    )
