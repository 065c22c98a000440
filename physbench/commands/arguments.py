"""Command-line arguments that several commands share, so that one flag means one thing
everywhere: the scene (``--scene NAME|FILE``), the unknowns (``--params``), ``-q/--quiet``,
``--json``, ``--out``, ``KEY=VALUE`` options and the renderer choice (``--renderer``,
``--renderer-option``, ``--resolution``, ``--render-mode``).

The vocabulary (tests/commands/test_vocabulary.py walks every parser against it):

- ``--out`` names the file or folder that holds a command's result; other files it can write
  have flags named for what they are (``--preview``, ``--plot``, ``--report``, ``--plate``,
  ``--track-out``, ``--save-observation``). Every file written is echoed as ``wrote PATH`` on
  stderr.
- ``--json`` is a switch: the result as JSON on stdout, instead of the text. A JSON file goes
  through ``--out``.
- ``--scene`` takes a registered name or a scene TOML file. It defaults to
  :data:`DEFAULT_SCENE` where the command makes its own data (run, simulate, train) and is
  required where it must describe given data (track, discover).
- ``--params`` takes one set of unknowns spelled ``mass+elasticity``, ``mass,elasticity`` or
  ``mass elasticity`` (:func:`physbench.unknowns.split_params`).
- ``-q/--quiet`` on every command that prints more than its result or shows progress; progress
  goes to stderr and only on a terminal (:mod:`physbench.commands.console`).
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from typing import Any

from physbench.limits import MAX_RESOLUTION, MAX_SCENE_ARGUMENT, MAX_SEED

#: Kept here (not imported from physbench.render.base) so building a parser imports nothing heavy.
RENDER_MODES = ("mark", "instance", "mask", "rgb")
#: physbench.experiment.DEFAULT_SCENE, for the same reason.
DEFAULT_SCENE = "three_circles"
#: The epilog of the commands that refuse a job too big for this machine (physbench.cost; kept
#: here so that building a parser imports nothing else).
SIZE_CHECK_HELP = (
    "Before any work, the memory and time the job needs are estimated from its sizes (frames, "
    "substeps, bodies, resolution, iterations, seeds, samples); a job that needs more memory than "
    "is available or more than 24 h of compute is refused, naming the estimate. Set the "
    "environment variable PHYSBENCH_NO_SIZE_CHECK=1 to run it anyway (docs/architecture.md)."
)


def bounded_int(low: int, high: int | None = None) -> Callable[[str], int]:
    """An argparse ``type=`` that accepts whole numbers in ``[low, high]`` (no upper bound when
    ``high`` is ``None``); the error names the value and the range."""
    accepted = f"a whole number >= {low}" if high is None else f"a whole number in [{low}, {high}]"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {accepted}") from None
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"{value} is not {accepted}")
        return value

    parse.__name__ = "whole number"  # argparse names the type in its own messages
    return parse


def bounded_float(low: float, high: float) -> Callable[[str], float]:
    """An argparse ``type=`` that accepts finite numbers in ``[low, high]``; the error names the
    value and the range."""
    accepted = f"a finite number in [{low:g}, {high:g}]"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {accepted}") from None
        if not (math.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(f"{text} is not {accepted}")
        return value

    parse.__name__ = "number"
    return parse


#: ``type=`` for counts that must be at least 1 (iterations, validation groups, intervals).
positive_int = bounded_int(1)
#: ``type=`` for counts where 0 means "none" (threads, evaluation seeds).
nonnegative_int = bounded_int(0)
#: ``type=`` for ``--seed``.
seed_int = bounded_int(0, MAX_SEED)
#: ``type=`` for ``--resolution``.
resolution_int = bounded_int(1, MAX_RESOLUTION)


def scene_argument(text: str) -> str:
    """``type=`` of ``--scene``: a name or path no longer than :data:`MAX_SCENE_ARGUMENT`."""
    if len(text) > MAX_SCENE_ARGUMENT:
        raise argparse.ArgumentTypeError(
            f"{text[:40]!r}... ({len(text)} characters) is longer than a scene name or path can "
            f"be; expected at most {MAX_SCENE_ARGUMENT} characters"
        )
    return text


def add_scene_argument(p: argparse.ArgumentParser, *, required: bool, help: str = "") -> None:
    """``--scene NAME|FILE``: a registered scene or a scene TOML; ``help`` adds what the command
    does with it. Not given, it parses as ``None`` (``run`` then takes an observation file's own
    scene) and stands for :data:`DEFAULT_SCENE`. Read it with
    :func:`physbench.scenes.resolve_scene`."""
    p.add_argument(
        "--scene",
        type=scene_argument,
        required=required,
        default=None,
        metavar="NAME|FILE",
        help="registered scene (see `physbench scenes`) or scene .toml file"
        + (f"; {help}" if help else "")
        + ("" if required else f" (default: {DEFAULT_SCENE})"),
    )


def add_params_argument(p: argparse.ArgumentParser, *, help: str = "") -> None:
    """``--params``: one set of unknowns, as words, or joined by ``+`` or ``,``; read it with
    :func:`physbench.unknowns.split_params`."""
    p.add_argument(
        "--params",
        nargs="+",
        default=["mass"],
        metavar="PARAM",
        help="unknown parameters to identify: mass, or mass elasticity, mass+elasticity, "
        "mass,elasticity" + (f"; {help}" if help else "") + " (default: mass)",
    )


def add_quiet_argument(p: argparse.ArgumentParser, help: str) -> None:
    """``-q/--quiet``: no progress display; ``help`` says what is still printed."""
    p.add_argument("-q", "--quiet", action="store_true", help=f"no progress display; {help}")


def add_json_argument(p: argparse.ArgumentParser, what: str) -> None:
    """``--json``: ``what`` as JSON on stdout instead of the text."""
    p.add_argument(
        "--json",
        action="store_true",
        help=f"print {what} as JSON on stdout instead of the text (a file: --out FILE.json)",
    )


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
        type=resolution_int,
        default=None if from_frames else resolution,
        metavar="PX",
        help="frame width in pixels (default: "
        + ("the frames' width" if from_frames else str(resolution))
        + ")",
    )
    # The old spelling --mode still parses; hidden so that help shows one name.
    p.add_argument("--mode", dest="render_mode", choices=RENDER_MODES, help=argparse.SUPPRESS)
    p.add_argument(
        "--render-mode",
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
    from physbench.components import make_renderer

    name, options = renderer_choice(args)
    return make_renderer(name, options, resolution=args.resolution, mode=args.render_mode)


def add_video_input_arguments(group: argparse._ActionsContainer) -> None:
    """The flags that say how to read a camera's video: ``--calibration``, ``--background``,
    ``--start``, ``--end``, ``--allow-gaps`` (the same in ``track``, ``run --video`` and
    ``discover VIDEO``)."""
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
    group.add_argument(
        "--allow-gaps",
        action="store_true",
        help="keep the tracks of a body lost in more than a tenth of the frames where it was in "
        "view (default: that is an error, which says from when to when it was lost)",
    )
