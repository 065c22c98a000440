"""Command-line arguments that several commands share, so that one flag means one thing
everywhere: the scene (``--scene NAME|FILE``), the unknowns (``--params``), ``-q/--quiet``,
``--json``, ``--out``, ``KEY=VALUE`` options and the renderer choice (``--renderer``,
``--renderer-option``, ``--resolution``, ``--render-mode``).

The vocabulary (tests/commands/test_vocabulary.py walks every parser against it):

- ``--out`` names the file or folder that holds a command's result; other files it can write
  have flags named for what they are (``--preview``, ``--plot``, ``--report``, ``--plate``,
  ``--track-out``, ``--save-observation``). Every file written is echoed as ``wrote PATH`` on
  stderr (not with ``-q``).
- ``--json`` is a switch: the result as JSON on stdout, instead of the text. A JSON file goes
  through ``--out``.
- ``--scene`` takes a registered name or a scene TOML file. It defaults to
  :data:`DEFAULT_SCENE` where the command makes its own data (run, simulate, train) and is
  required where it must describe given data (track, discover).
- ``--params`` takes one set of unknowns spelled ``mass+elasticity``, ``mass,elasticity`` or
  ``mass elasticity`` (:func:`physbench.unknowns.split_params`).
- ``-q/--quiet`` on every command that prints more than its result or shows progress: no
  progress and no ``wrote PATH`` lines, only the result (errors and warnings still go to stderr);
  progress goes to stderr and only on a terminal (:mod:`physbench.commands.console`).
- ``--bodies`` takes body names spelled as ``--params`` spells unknowns (:func:`split_bodies`).
- A text option never takes an empty value (:func:`refuse_empty_values`): ``--engine ''`` is an
  error, not the default.
"""

from __future__ import annotations

import argparse
import inspect
import json
import math
import re
from collections.abc import Callable, Mapping
from typing import Any

from physbench import numeric
from physbench.limits import MAX_SCENE_ARGUMENT
from physbench.numeric import Number, finite, whole

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


def bounded_int(low: int, high: int | None = None) -> Number:
    """An argparse ``type=`` that accepts whole numbers in ``[low, high]`` (no upper bound when
    ``high`` is ``None``); the error names the value and the range (:mod:`physbench.numeric`)."""
    return whole(low, high)


def bounded_float(low: float, high: float) -> Number:
    """An argparse ``type=`` that accepts finite numbers in ``[low, high]``; the error names the
    value and the range (:mod:`physbench.numeric`)."""
    return finite(low, high)


#: ``type=`` for counts that must be at least 1 (iterations, validation groups, intervals).
positive_int = numeric.COUNT
#: ``type=`` for counts where 0 means "none" (threads, evaluation seeds).
nonnegative_int = numeric.COUNT_OR_NONE
#: ``type=`` for ``--seed``.
seed_int = numeric.SEED
#: ``type=`` for ``--resolution``.
resolution_int = numeric.RESOLUTION


def scene_argument(text: str) -> str:
    """``type=`` of ``--scene``: a name or path, not empty and no longer than
    :data:`MAX_SCENE_ARGUMENT`."""
    if not text.strip():
        raise argparse.ArgumentTypeError(
            f"{text!r} is empty; expected a registered scene (see `physbench scenes`) or a scene "
            ".toml file"
        )
    if len(text) > MAX_SCENE_ARGUMENT:
        raise argparse.ArgumentTypeError(
            f"{text[:40]!r}... ({len(text)} characters) is longer than a scene name or path can "
            f"be; expected at most {MAX_SCENE_ARGUMENT} characters"
        )
    return text


def _nonempty(action: argparse.Action) -> Callable[[str], str]:
    """``type=`` of a text option: any text but an empty (or blank) one."""
    expected = action.metavar if isinstance(action.metavar, str) else action.dest.upper()

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError(f"{text!r} is empty; expected a non-empty {expected}")
        return text

    parse.__name__ = "text"
    return parse


def refuse_empty_values(p: argparse.ArgumentParser) -> None:
    """Make every text option and argument of ``p`` refuse an empty value, which the commands
    would otherwise read as "not given" and replace by a default (``--engine ''`` running pymunk,
    ``--plot ''`` writing no plot). Options whose default is the empty text keep accepting it.
    Called by :func:`physbench.cli.build_parser` on every command's parser."""
    for action in p._actions:
        if (
            isinstance(action, argparse._StoreAction | argparse._AppendAction)
            and action.type is None
            and action.choices is None
            and action.default != ""
        ):
            action.type = _nonempty(action)


def split_bodies(items: list[str]) -> tuple[str, ...]:
    """``--bodies``: body names spelled as ``--params`` spells unknowns, ``a b``, ``a+b``, ``a,b``
    or as several words; no name twice."""
    from physbench.errors import PhysbenchError

    names = tuple(n for item in items for n in re.split(r"[\s,+]+", item.strip()) if n)
    if not names or len(set(names)) != len(names):
        raise PhysbenchError(
            f"--bodies {' '.join(items)!r}: expected body names such as a, a+b, a,b or a b "
            "(no repeats)"
        )
    return names


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
    """``-q/--quiet``: no progress display and no ``wrote PATH`` lines; ``help`` says what is still
    printed."""
    p.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help=f"no progress display and no 'wrote' lines; {help}",
    )


def add_json_argument(p: argparse.ArgumentParser, what: str) -> None:
    """``--json``: ``what`` as JSON on stdout instead of the text."""
    p.add_argument(
        "--json",
        action="store_true",
        help=f"print {what} as JSON on stdout instead of the text (a file: --out FILE.json)",
    )


def _finite(value: Any) -> bool:
    """Whether every number in the JSON value ``value`` is finite."""
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list):
        return all(_finite(v) for v in value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    return True


class _NonFinite(Exception):
    """JSON's NaN, Infinity or -Infinity in a ``KEY=VALUE`` value."""


def _refuse_constant(name: str) -> float:
    raise _NonFinite(name)


def parse_key_values(items: list[str], flag: str) -> dict[str, Any]:
    """``["startup=5", "sampler=cmaes"]`` -> ``{"startup": 5, "sampler": "cmaes"}``: values parse
    as JSON, else stay text; a number that is not finite (``NaN``, ``Infinity``, ``1e999``) is
    refused, as every numeric setting is (:mod:`physbench.numeric`). ``flag`` names the option in
    errors."""
    from physbench.errors import PhysbenchError

    out: dict[str, Any] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        if not sep or not key.strip():
            raise PhysbenchError(f"{flag} {item!r}: expected KEY=VALUE, e.g. {flag} startup=5")
        try:
            value = json.loads(raw, parse_constant=_refuse_constant)
        except _NonFinite:
            value = math.nan
        except (ValueError, RecursionError):
            value = raw
        if not _finite(value):
            raise PhysbenchError(
                f"{flag} {item!r}: {raw.strip()} is not a finite number; a value is a finite "
                "number, text or JSON"
            )
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
    """The renderer name (the default when not given) and its options from the parsed ``args``,
    whose keys are checked against the options ``-R`` can set (:func:`check_renderer_options`)."""
    from physbench.render.base import DEFAULT_RENDERER

    name = args.renderer or DEFAULT_RENDERER
    options = parse_key_values(args.renderer_option, "--renderer-option")
    check_renderer_options(name, options)
    return name, options


#: The renderer keywords physbench sets itself: ``--resolution`` and ``--render-mode`` give them.
STANDARD_RENDERER_KEYWORDS = ("resolution", "mode")


def check_renderer_options(name: str, options: Mapping[str, Any]) -> None:
    """Refuse a ``-R`` key the registered renderer ``name`` does not take, listing only the options
    ``-R`` can set (:func:`physbench.components.options_of`: not ``resolution`` and ``mode``, which
    have flags of their own and a message of their own in
    :func:`~physbench.components.make_renderer`). A renderer whose options cannot be read from it
    (``**kwargs`` without ``option_names()``), or an unknown name, is left to
    :func:`~physbench.components.create`."""
    from physbench.components import options_of, origin
    from physbench.errors import OptionError, UnknownNameError
    from physbench.plugins import get_registry

    try:
        cls = get_registry().get("renderer", name)
    except UnknownNameError:
        return  # said where the renderer is built, in the words of the command's setting
    try:
        params = inspect.signature(cls).parameters.values()
    except (TypeError, ValueError):
        return
    if any(p.kind == p.VAR_KEYWORD for p in params) and not callable(
        getattr(cls, "option_names", None)
    ):
        return
    takes = options_of(cls, dict.fromkeys(STANDARD_RENDERER_KEYWORDS))
    unknown = [k for k in options if k not in takes and k not in STANDARD_RENDERER_KEYWORDS]
    if unknown:
        key = unknown[0]
        raise OptionError(
            f"-R {key}={json.dumps(options[key])}: renderer {name!r} ({origin('renderer', name)}) "
            f"has no option {key!r}; the options -R can set: {', '.join(takes) or 'none'}"
        )


def make_renderer_from(args: argparse.Namespace) -> Any:
    """The renderer the parsed ``args`` choose, built with their resolution and render mode."""
    from physbench.components import make_renderer

    name, options = renderer_choice(args)
    return make_renderer(name, options, resolution=args.resolution, mode=args.render_mode)


def add_video_input_arguments(group: argparse._ActionsContainer) -> None:
    """The flags that say how to read a camera's video: ``--calibration``, ``--background``,
    ``--start``, ``--end``, ``--allow-gaps``, ``--transfer``, ``--capture-fps`` (the same in
    ``track``, ``run --video`` and ``discover VIDEO``)."""
    from physbench.video.transfer import AUTO, DEFAULT, TRANSFERS

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
        "--start",
        type=numeric.SECONDS,
        default=None,
        metavar="S",
        help="skip the video's first S seconds",
    )
    group.add_argument(
        "--end",
        type=numeric.SECONDS,
        default=None,
        metavar="S",
        help="stop at S seconds into the video",
    )
    group.add_argument(
        "--allow-gaps",
        action="store_true",
        help="keep the tracks of a body lost in more than a tenth of the frames where it was in "
        "view (default: that is an error, which says from when to when it was lost)",
    )
    group.add_argument(
        "--transfer",
        choices=(AUTO, *TRANSFERS),
        default=None,
        help="how the video's pixel values encode light, decoded to linear light before "
        f"tracking (default {AUTO}: the video's tag, else {DEFAULT}; phones tag bt709)",
    )
    group.add_argument(
        "--capture-fps",
        type=numeric.POSITIVE,
        default=None,
        metavar="FPS",
        help="the rate a slow-motion video was filmed at, where its file plays slower (a "
        "phone's 240 fps stored to play at 30): the frames' times become real seconds "
        "(--start and --end stay the player's)",
    )
