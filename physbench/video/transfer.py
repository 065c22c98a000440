"""Transfer functions: how a video's pixel values relate to the light the camera saw.

The tracker weighs a turning body's pixels by the share of the exposure each saw the body,
unmixing each pixel as ``alpha * body + (1 - alpha) * background`` (a blurred or partly covered
pixel), which holds in linear light only. Cameras encode a transfer function (BT.709, sRGB:
roughly a 1/2.2 power), so those pixels and the background there are decoded to linear light
first (:class:`Decoder`). Measured on six swinging arms filmed by the field camera (gamma 2.2):
the centre was 2.5-6.2 px off read as linear, 0.9-3.9 px decoded (median 4.6 -> 1.4 px).

Only that step is decoded. Decoding whole frames to 8-bit linear light instead helped the arms
as much but cost the discs: a dark ball on a lighter wall has half its contrast over the same
noise in linear light, and its outline fit failed more often (a thrown ball: 0.47 -> 0.83 px).
A disc's outline is placed at the half-way point of its edge, which a transfer function moves
alike all round, so its centre does not need linear light.

Where the transfer comes from (:func:`resolve`): a named ``transfer`` option; else the video's
tag (the H.264/HEVC VUI ``transfer_characteristics``, ITU-T H.273 codes: :data:`TAGS`); else
:data:`DEFAULT`. physbench's own cameras tag what they write (:data:`CODES`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from physbench.errors import PhysbenchError

if TYPE_CHECKING:  # the commands read the names at argument parsing, before numpy is needed
    import numpy as np

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
#: ITU-T H.273 codes of the HDR curves a phone records with (HDR video is on by default on
#: many recent phones): physbench reads their pixel values as they are, with no HDR curve.
HDR = {16: "PQ", 18: "HLG"}
#: The code each transfer is tagged with when written.
CODES = {"bt709": 1, "gamma2.2": 4, "gamma2.8": 5, "linear": 8, "srgb": 13}
#: The transfer of a video with no tag. A wrong guess costs alike both ways (an arm's centre: a
#: ``camera`` clip read as sRGB 2.3-3.0 px off instead of 0.3-0.6; field-camera clips read as
#: linear 4.6 px instead of 1.4, medians), physbench's clips from before the tags are untagged
#: and linear, and phones tag their video; untagged footage from a real camera needs
#: ``--transfer srgb`` (docs/video.md).
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


def hdr_from_tag(code: object) -> str | None:
    """The HDR curve (``"PQ"``, ``"HLG"``) a stream's ``transfer_characteristics`` code names, or
    ``None``."""
    try:
        return HDR.get(int(code))  # type: ignore[call-overload]
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
    import numpy as np

    v = np.clip(np.asarray(values, dtype=float), 0.0, 1.0)
    name = check_transfer(name, auto=False)
    if name == "srgb":
        return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    if name == "bt709":
        return np.where(v < 0.081, v / 4.5, ((v + 0.099) / 1.099) ** (1 / 0.45))
    if name.startswith("gamma"):
        return v ** float(name[len("gamma") :])
    return v


class Decoder:
    """Pixel values of transfer ``name`` (grey levels, 0-255, any float) -> linear light on the
    same scale (the identity for ``linear``)."""

    def __init__(self, name: str) -> None:
        self.name = check_transfer(name, auto=False)

    def __call__(self, levels: np.ndarray) -> np.ndarray:
        if self.name == "linear":
            return levels
        import numpy as np

        return 255.0 * to_linear(self.name, np.asarray(levels, dtype=float) / 255.0)
