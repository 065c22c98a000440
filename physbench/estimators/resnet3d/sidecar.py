"""The weights sidecar's schema, checked when weights are loaded or listed, so that a hand-edited,
truncated or foreign ``NAME.json`` fails with what is wrong instead of deep inside torch.

Only what the estimator and evaluation read is checked (``data``, ``net``, ``ranges``,
``storage``, ``sha256``, ``scene``); the training record (``history``, ``training``, ...) is
informational and passes as it is.
"""

from __future__ import annotations

import math
from typing import Any

from physbench.errors import PhysbenchError

#: Sidecar ``storage`` value of weights kept as int8 with one float32 scale per output channel.
INT8 = "int8-per-output-channel"

# Input layout limits, the same for training (physbench train) and loading. Resolution: the
# stem (stride 2) and three strided stages shrink a frame 16x, so at 8 pixels the deepest stages
# already see one pixel, and the objects (a few pixels wide at the 64-pixel renders) are below a
# pixel after resizing; at 512, one sample's stem activations (widths[0] x 2·frames x R/2 x R/2
# float32) are 0.1-0.5 GB at the CPU widths and grow with R², so 4096 cannot fit in memory.
# Frames: parameters show in motion, which takes 2 frames at least; 64 is twice the default
# scenes' 30 (ball_drop records 60). A net claiming far more frames than a recording has gets
# all of it from time_indices: a layout it never saw.
RESOLUTION = (8, 512)
FRAMES = (2, 64)
_WIDTH = (1, 2048)  # the paper's full widths top out at 512
_BLOCKS = (1, 16)  # BasicBlocks per stage; ResNet-18 has 2
# The loop renders marked frames: channel 0 the other bodies, channel 1 the marked one.
IN_CHANNELS = 2

_NET_KEYS = {"n_outputs", "in_channels", "widths", "blocks", "dropout", "resolution", "frames"}
_DATA_REQUIRED = {"scene", "params"}
_DATA_KEYS = _DATA_REQUIRED | {
    "engine",
    "renderer",
    "renderer_options",
    "render_resolution",
    "resolution",
    "frames",
    "group",
    "scene_options",
    "blur_max",
    "blur_prob",
    "near",
    "near_scale",
}


class _Check:
    """Collects the first problem of one sidecar, named by its JSON path."""

    def __init__(self, where: str) -> None:
        self.where = where

    def fail(self, key: str, value: object, expected: str) -> PhysbenchError:
        shown = repr(value)
        shown = shown if len(shown) <= 80 else shown[:77] + "..."
        return PhysbenchError(f"{self.where}: {key} is {shown}, expected {expected}")

    def obj(self, value: object, key: str, required: set[str], allowed: set[str]) -> dict:
        if not isinstance(value, dict):
            raise self.fail(key, value, "a JSON object")
        missing = sorted(required - set(value))
        if missing:
            raise self.fail(key, value, f"an object with the keys {', '.join(missing)}")
        extra = sorted(set(value) - allowed)
        if extra:
            raise self.fail(
                f"{key}.{extra[0]}",
                value[extra[0]],
                f"no such key (known: {', '.join(sorted(allowed))})",
            )
        return value

    def integer(self, value: object, key: str, lo: int, hi: int) -> int:
        # bool is an int in Python, but ``true`` is never a meant count
        if not isinstance(value, int) or isinstance(value, bool) or not lo <= value <= hi:
            raise self.fail(key, value, f"an integer in {lo}..{hi}")
        return value

    def number(self, value: object, key: str, lo: float, hi: float) -> float:
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        if not ok or not math.isfinite(value) or not lo <= value <= hi:  # type: ignore[arg-type]
            bounds = f" in [{lo}, {hi}]" if math.isfinite(hi) else f" >= {lo}"
            raise self.fail(key, value, "a finite number" + ("" if math.isinf(lo) else bounds))
        return float(value)  # type: ignore[arg-type]

    def text(self, value: object, key: str) -> str:
        if not isinstance(value, str) or not value:
            raise self.fail(key, value, "a non-empty string")
        return value

    def mapping(self, value: object, key: str) -> dict:
        if not isinstance(value, dict):
            raise self.fail(key, value, "a JSON object")
        return value


def check(meta: object, where: str) -> dict[str, Any]:
    """``meta`` if it is a complete weights sidecar, else a PhysbenchError that names ``where``
    (the sidecar's path), the bad key and what it should be. Called on every load and listing."""
    c = _Check(where)
    if not isinstance(meta, dict):
        raise c.fail("the sidecar", meta, "a JSON object with data, net, ranges")
    for key in ("data", "net", "ranges"):
        if key not in meta:
            raise PhysbenchError(
                f"{where}: no {key!r} entry; a weights sidecar records data, net and ranges "
                "(physbench train writes them)"
            )
    if "scene" in meta:
        c.text(meta["scene"], "scene")
    params = _data(c, meta["data"])
    _net(c, meta["net"], meta["data"], params)
    ranges = c.mapping(meta["ranges"], "ranges")
    if set(ranges) != set(params):
        raise c.fail("ranges", ranges, f"the range of each of {', '.join(params)}")
    for p in params:
        lohi = ranges[p]
        if (
            not isinstance(lohi, list)
            or len(lohi) != 2
            or c.number(lohi[0], f"ranges.{p}[0]", -math.inf, math.inf)
            >= c.number(lohi[1], f"ranges.{p}[1]", -math.inf, math.inf)
        ):
            raise c.fail(f"ranges.{p}", lohi, "[low, high] with low < high")
    storage = meta.get("storage")
    if storage is not None and storage != INT8:
        raise c.fail("storage", storage, f"{INT8!r} or no storage (float tensors)")
    digest = meta.get("sha256")
    if digest is not None and not (
        isinstance(digest, str)
        and len(digest) == 64
        and all(ch in "0123456789abcdef" for ch in digest)
    ):
        raise c.fail("sha256", digest, "64 lowercase hex digits")
    return meta


def _data(c: _Check, data: object) -> tuple[str, ...]:
    """The checked ``data`` (a DataSpec); returns its parameter names."""
    d = c.obj(data, "data", _DATA_REQUIRED, _DATA_KEYS)
    c.text(d["scene"], "data.scene")
    params = d["params"]
    if (
        not isinstance(params, list)
        or not params
        or not all(isinstance(p, str) and p for p in params)
        or len(set(params)) != len(params)
    ):
        raise c.fail("data.params", params, "a non-empty list of distinct parameter names")
    for key in ("engine", "renderer"):
        if key in d:
            c.text(d[key], f"data.{key}")
    for key in ("renderer_options", "scene_options"):
        if key in d:
            c.mapping(d[key], f"data.{key}")
    if "render_resolution" in d:
        c.integer(
            d["render_resolution"], "data.render_resolution", RESOLUTION[0], 4 * RESOLUTION[1]
        )
    if "resolution" in d:
        c.integer(d["resolution"], "data.resolution", *RESOLUTION)
    if "frames" in d:
        c.integer(d["frames"], "data.frames", *FRAMES)
    if "group" in d:
        c.integer(d["group"], "data.group", 2, 1024)  # a sample is a pair of simulations
    if "blur_max" in d:
        c.number(d["blur_max"], "data.blur_max", 0.0, math.inf)
    if "blur_prob" in d:
        c.number(d["blur_prob"], "data.blur_prob", 0.0, 1.0)
    if "near" in d:
        c.number(d["near"], "data.near", 0.0, 1.0)
    if "near_scale" in d:
        c.number(d["near_scale"], "data.near_scale", 0.0, 1.0)
    return tuple(params)


def _net(c: _Check, net: object, data: dict[str, Any], params: tuple[str, ...]) -> None:
    """Checks ``net`` (a NetConfig) and that it takes the inputs ``data`` describes."""
    n = c.obj(net, "net", _NET_KEYS, _NET_KEYS)
    c.integer(n["n_outputs"], "net.n_outputs", len(params), len(params))
    c.integer(n["in_channels"], "net.in_channels", IN_CHANNELS, IN_CHANNELS)
    for key, (lo, hi) in (("widths", _WIDTH), ("blocks", _BLOCKS)):
        value = n[key]
        if not isinstance(value, list) or len(value) != 4:
            raise c.fail(f"net.{key}", value, f"a list of 4 integers in {lo}..{hi}")
        for i, v in enumerate(value):
            c.integer(v, f"net.{key}[{i}]", lo, hi)
    c.number(n["dropout"], "net.dropout", 0.0, 0.99)
    c.integer(n["resolution"], "net.resolution", *RESOLUTION)
    c.integer(n["frames"], "net.frames", *FRAMES)
    from physbench.estimators.resnet3d.training_data import DataSpec

    # Training made the inputs with data's layout; an absent key means DataSpec's default.
    for key in ("resolution", "frames"):
        used = data.get(key, getattr(DataSpec, key))
        if used != n[key]:
            raise c.fail(f"net.{key}", n[key], f"data.{key} ({used}), the layout it was trained on")
