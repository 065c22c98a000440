"""Transfer functions: how a video's pixel values relate to the light the camera saw.

The tracker models a pixel as a mix of a body and the background weighted by how long each was
seen (a blurred or partly covered pixel), which holds in linear light only. Real cameras encode
a transfer function (BT.709, sRGB: roughly a 1/2.2 power), so every frame and the background are
decoded to linear light (:class:`Decoder`) before the tracker sees them. Measured on a swinging
arm filmed by the field camera (gamma 2.2, open shutter): the arm's centre was 5.1 px off read
as linear, 2.6 px decoded; the same camera writing linear light gave 2.8 px.

Where the transfer comes from (:func:`resolve`): a named ``transfer`` option; else the video's
tag (the H.264/HEVC VUI ``transfer_characteristics``, ITU-T H.273 codes: :data:`TAGS`); else
:data:`DEFAULT`. physbench's own cameras tag what they write (:data:`CODES`).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from physbench.errors import PhysbenchError

#: The transfer functions known, by name.
TRANSFERS = ("linear", "srgb", "bt709", "gamma2.2", "gamma2.8")
#: The option's value that reads the video's tag (and :data:`DEFAULT` where it has none).
AUTO = "auto"
#: ITU-T H.273 transfer characteristics -> name (1, 6, 14, 15: BT.709's curve, also BT.601's
#: and BT.2020's at 10 and 12 bits). Other codes (unspecified, PQ, HLG, log) are not read.
TAGS = {
    1: "bt709",
    6: "bt709",
    14: "bt709",
    15: "bt709",
    4: "gamma2.2",
    5: "gamma2.8",
    8: "linear",
    13: "srgb",
}
#: The code each transfer is tagged with when written.
CODES = {"bt709": 1, "gamma2.2": 4, "gamma2.8": 5, "linear": 8, "srgb": 13}
#: The transfer of a video with no tag. A wrong guess costs alike both ways (an arm's centre: a
#: linear clip read as sRGB 3.0 px off instead of 0.3; a gamma clip read as linear 5.1 px instead
#: of 2.6), physbench's clips from before the tags are untagged and linear, and phones tag
#: their video; untagged footage from a real camera needs ``--transfer srgb`` (docs/video.md).
DEFAULT = "linear"


class TransferError(PhysbenchError, ValueError):
    """An unknown transfer function: names the value and those accepted."""


def check_transfer(name: object, *, auto: bool = True) -> str:
    """``name`` if it names a transfer function (or :data:`AUTO` where ``auto``), else
    :class:`TransferError`."""
    known = (*TRANSFERS, AUTO) if auto else TRANSFERS
    if not isinstance(name, str) or name.lower() not in known:
        raise TransferError(f"transfer = {name!r}: expected one of {', '.join(known)}")
    return name.lower()


def from_tag(code: object) -> str | None:
    """The transfer a stream's ``transfer_characteristics`` code names, or ``None`` (untagged,
    or a curve physbench does not read)."""
    try:
        return TAGS.get(int(code))  # type: ignore[call-overload]
    except (TypeError, ValueError):
        return None


def resolve(option: str | None, tag: str | None) -> tuple[str, str]:
    """The transfer to read a video with and where it came from (``option``, ``tag`` or
    ``default``): a named ``option`` first, then the video's ``tag``, then :data:`DEFAULT`."""
    option = check_transfer(AUTO if option is None else option)
    if option != AUTO:
        return option, "option"
    if tag is not None:
        return check_transfer(tag, auto=False), "tag"
    return DEFAULT, "default"


def to_linear(name: str, values: np.ndarray) -> np.ndarray:
    """Code values in ``[0, 1]`` -> linear light in ``[0, 1]`` through transfer ``name``'s
    inverse."""
    v = np.clip(np.asarray(values, dtype=float), 0.0, 1.0)
    name = check_transfer(name, auto=False)
    if name == "srgb":
        return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    if name == "bt709":
        return np.where(v < 0.081, v / 4.5, ((v + 0.099) / 1.099) ** (1 / 0.45))
    if name.startswith("gamma"):
        return v ** float(name[len("gamma") :])
    return v


@cache
def _table(name: str) -> np.ndarray:
    levels = to_linear(name, np.arange(256) / 255.0)
    table = np.clip(np.rint(255.0 * levels), 0, 255).astype(np.uint8)
    table.flags.writeable = False
    return table


class Decoder:
    """8-bit pixels of transfer ``name`` -> 8-bit linear light (a look-up table; the identity
    for ``linear`` costs nothing)."""

    def __init__(self, name: str) -> None:
        self.name = check_transfer(name, auto=False)
        self.table = None if self.name == "linear" else _table(self.name)

    def __call__(self, image: np.ndarray) -> np.ndarray:
        return image if self.table is None else self.table[image]
