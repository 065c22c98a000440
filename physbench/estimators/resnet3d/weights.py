"""Weights as safetensors plus a JSON sidecar; loading never unpickles.

``NAME.safetensors`` holds the tensors, ``NAME.json`` the scene, unknowns, ranges, normalisation,
architecture, input layout, training budget, validation error and physbench version. Shipped
weights live in ``physbench/estimators/resnet3d/weights/``; ``PHYSBENCH_WEIGHTS`` (a path list)
adds folders searched first.
"""

from __future__ import annotations

import hashlib
import json
import os
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from physbench.errors import PhysbenchError
from physbench.estimators.resnet3d import sidecar
from physbench.estimators.resnet3d.sidecar import INT8

SHIPPED = Path(__file__).with_name("weights")
_SCALE = ".int8_scale"


@dataclass(frozen=True)
class WeightsInfo:
    path: Path  # the .safetensors file
    meta: dict[str, Any]

    @property
    def scene(self) -> str:
        """The scene's name (weights trained on a scene file record it beside the file's path)."""
        return str(self.meta.get("scene") or self.meta["data"]["scene"])

    @property
    def params(self) -> tuple[str, ...]:
        return tuple(self.meta["data"]["params"])


def save(path: str | Path, state: dict[str, Any], meta: dict[str, Any]) -> Path:
    """Write ``state`` (name -> tensor) and ``meta``; returns the .safetensors path. Each file is
    replaced atomically and readable as the umask allows; the sidecar records the tensors' SHA-256,
    so a reader that catches the pair between the two replacements refuses it instead of
    mixing one save's tensors with another's normalisation."""
    from safetensors.torch import save as encode

    path = Path(path).with_suffix(".safetensors")
    path.parent.mkdir(parents=True, exist_ok=True)
    data = encode({k: v.detach().contiguous().cpu() for k, v in state.items()})
    meta = {**meta, "sha256": hashlib.sha256(data).hexdigest()}
    tmp, side, side_tmp = (path.with_suffix(s) for s in (".tmp", ".json", ".json.tmp"))
    tmp.write_bytes(data)
    side_tmp.write_text(json.dumps(meta, indent=2, sort_keys=True))
    os.replace(tmp, path)
    os.replace(side_tmp, side)
    return path


def read(path: str | Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """(tensors, meta) of any pair :func:`save` wrote (training checkpoints too); int8 storage
    comes back as float32. Called where the sidecar is not a model's: :func:`load` checks that.
    A sidecar whose ``sha256`` is not the tensors' is refused, and so is a file that is not
    safetensors (truncated, or a pickle renamed): it is never unpickled."""
    return _pair(path, model=False)


def load(path: str | Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """(tensors, meta) of model weights, checked before anything builds a net from them: the
    sidecar's schema (:mod:`.sidecar`) and that the tensors are exactly the architecture's,
    names and shapes, finite floats. Called by the estimator's start, evaluation and
    ``train --init``."""
    return _pair(path, model=True)


def _pair(path: str | Path, *, model: bool) -> tuple[dict[str, Any], dict[str, Any]]:
    path = Path(path).with_suffix(".safetensors")
    side = path.with_suffix(".json")
    if not path.is_file() or not side.is_file():
        raise PhysbenchError(f"weights {str(path)!r} need both {path.name} and {side.name}")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise PhysbenchError(f"weights {str(path)!r} cannot be read: {exc}") from None
    meta = read_sidecar(side)
    if model:  # the schema first: its message says more than a tensor-level symptom would
        sidecar.check(meta, f"weights sidecar {str(side)!r}")
    digest = meta.get("sha256")
    if digest is not None and hashlib.sha256(data).hexdigest() != digest:
        raise PhysbenchError(
            f"weights {str(path)!r}: {side.name} describes other tensors (its sha256 "
            f"{str(digest)[:12]}… is not the file's): the pair comes from two saves, e.g. an "
            "interrupted one; save or train again"
        )
    tensors = _decode(data, path)
    if meta.get("storage") == INT8:
        tensors = dequantize(tensors, where=f"weights {str(path)!r}")
    elif meta.get("storage") is not None:
        raise PhysbenchError(
            f"weights {str(path)!r}: {side.name} has storage {meta['storage']!r}, expected "
            f"{INT8!r} or none (float tensors)"
        )
    elif any(name.endswith(_SCALE) for name in tensors):
        raise PhysbenchError(
            f"weights {str(path)!r} hold int8 tensors with scales but {side.name} has no "
            f"storage; expected storage {INT8!r}"
        )
    if model:
        _match(tensors, meta["net"], path)
    return tensors, meta


def read_sidecar(side: Path) -> dict[str, Any]:
    """The JSON object in ``side``, or a PhysbenchError saying why it is not one."""
    try:
        meta = json.loads(side.read_bytes())
    except OSError as exc:
        raise PhysbenchError(f"weights sidecar {str(side)!r} cannot be read: {exc}") from None
    except (ValueError, RecursionError) as exc:  # invalid JSON or text, or nested too deep
        raise PhysbenchError(
            f"weights sidecar {str(side)!r} is not valid JSON ({exc}); expected the object "
            "physbench train writes beside NAME.safetensors"
        ) from None
    if not isinstance(meta, dict):
        raise PhysbenchError(
            f"weights sidecar {str(side)!r} holds a JSON {type(meta).__name__}, expected an object"
        )
    return meta


def _decode(data: bytes, path: Path) -> dict[str, Any]:
    from safetensors import SafetensorError
    from safetensors.torch import load as decode

    try:
        return decode(data)
    except (SafetensorError, ValueError, OverflowError) as exc:
        raise PhysbenchError(
            f"weights {str(path)!r} ({len(data)} bytes) is not a readable safetensors file "
            f"({exc}); expected the tensors physbench train or weights.save wrote, complete"
        ) from None


def _match(tensors: dict[str, Any], net: dict[str, Any], path: Path) -> None:
    """Refuses tensors that are not the state of the net ``net`` describes, before
    ``load_state_dict`` would fail (or, for shapes it broadcasts, not)."""
    import torch

    from physbench.estimators.resnet3d.network import NetConfig, build_net

    with torch.device("meta"):  # shapes only: no memory, no initialisation cost
        want = {
            k: tuple(v.shape) for k, v in build_net(NetConfig.from_dict(net)).state_dict().items()
        }
    where = f"weights {str(path)!r}"
    missing, extra = sorted(set(want) - set(tensors)), sorted(set(tensors) - set(want))
    if missing or extra:
        raise PhysbenchError(
            f"{where} do not fit the architecture in their sidecar's net: missing tensors "
            f"{missing[:5] or 'none'}, unexpected {extra[:5] or 'none'}"
        )
    for name, shape in want.items():
        t = tensors[name]
        if tuple(t.shape) != shape:
            raise PhysbenchError(
                f"{where}: tensor {name!r} has shape {tuple(t.shape)}, the sidecar's net "
                f"expects {shape}"
            )
        if not t.is_floating_point() or not bool(torch.isfinite(t).all()):
            raise PhysbenchError(f"{where}: tensor {name!r} ({t.dtype}) is not all finite floats")


def quantize(state: dict[str, Any]) -> dict[str, Any]:
    """Symmetric int8 per output channel for every weight of 2+ dims (scale = max|w| / 127), float16
    for the rest: a quarter of float32's size for convolution-heavy nets."""
    import torch

    out: dict[str, Any] = {}
    for name, t in state.items():
        t = t.detach().float().cpu()
        if t.dim() >= 2:
            scale = t.abs().flatten(1).amax(dim=1).clamp_min(1e-12) / 127.0
            shape = (-1,) + (1,) * (t.dim() - 1)
            out[name] = torch.round(t / scale.view(shape)).clamp(-127, 127).to(torch.int8)
            out[name + _SCALE] = scale
        else:
            out[name] = t.half()
    return out


def dequantize(tensors: dict[str, Any], where: str = "weights") -> dict[str, Any]:
    """Float32 tensors back from :func:`quantize`'s output; a scale without its tensor, or one
    that is not a float per output channel, is refused (naming ``where``)."""
    out: dict[str, Any] = {}
    for name, t in tensors.items():
        if name.endswith(_SCALE):
            if name[: -len(_SCALE)] not in tensors:
                raise PhysbenchError(
                    f"{where}: scale {name!r} has no tensor {name[: -len(_SCALE)]!r}"
                )
            continue
        scale = tensors.get(name + _SCALE)
        if scale is None:
            out[name] = t.float()
            continue
        if t.dim() < 1 or not scale.is_floating_point() or tuple(scale.shape) != t.shape[:1]:
            raise PhysbenchError(
                f"{where}: scale of {name!r} has shape {tuple(scale.shape)} ({scale.dtype}), "
                f"expected ({t.shape[0] if t.dim() else 1},) floats, one per output channel"
            )
        out[name] = t.float() * scale.float().view((-1,) + (1,) * (t.dim() - 1))
    return out


def named_dirs(variable: str) -> list[Path]:
    """The folders the path list in the environment ``variable`` names, in order."""
    return [Path(p) for p in os.environ.get(variable, "").split(os.pathsep) if p]


def search_dirs() -> list[Path]:
    return [*named_dirs("PHYSBENCH_WEIGHTS"), SHIPPED]


def empty_folder(
    variable: str, folder: Path, what: str, skipped: list[str], train: str = "physbench train"
) -> PhysbenchError:
    """The error for a folder that ``variable`` names but that holds no valid ``what`` weights:
    named on purpose, it is a mistake (a typo, a training that wrote elsewhere), not a reason to
    fall back silently to the shipped weights. ``skipped``: why each file there was refused;
    ``train``: the command that writes such weights."""
    if not folder.exists():
        why = "which does not exist"
    elif not folder.is_dir():
        why = "which is not a folder"
    elif skipped:
        why = f"which holds no valid {what} weights ({'; '.join(skipped)})"
    else:
        why = f"which holds no {what} weights (no NAME.safetensors with its NAME.json)"
    return PhysbenchError(
        f"{variable} names {str(folder)!r}, {why}; point {variable} at the output folder of "
        f"`{train}`, or take this folder off it"
    )


def _scan(folder: Path) -> tuple[list[WeightsInfo], list[str]]:
    """The weights in ``folder``, and why each other pair there was refused."""
    found, skipped = [], []
    for side in sorted(folder.glob("*.json")) if folder.is_dir() else []:
        st = side.with_suffix(".safetensors")
        if not st.is_file():
            continue
        try:
            meta = sidecar.check(read_sidecar(side), f"weights sidecar {str(side)!r}")
        except PhysbenchError as exc:
            skipped.append(f"{str(st)!r}: {exc}")
            continue
        found.append(WeightsInfo(st, meta))
    return found, skipped


def available() -> list[WeightsInfo]:
    """Every weights file found, searched folders first to last; called by :func:`find` and
    listings. A file whose sidecar is not a weights sidecar is skipped with a warning naming it,
    so one bad file in a ``PHYSBENCH_WEIGHTS`` folder does not break lookups of the others; a
    ``PHYSBENCH_WEIGHTS`` folder without any valid weights is an error (:func:`empty_folder`)."""
    out = []
    named = named_dirs("PHYSBENCH_WEIGHTS")
    for d in [*named, SHIPPED]:
        found, skipped = _scan(d)
        if not found and d in named:
            raise empty_folder("PHYSBENCH_WEIGHTS", d, "resnet3d", skipped)
        for why in skipped:
            warnings.warn(f"skipping weights {why}", UserWarning, stacklevel=2)
        out.extend(found)
    return out


def find(scene: str, params: tuple[str, ...]) -> WeightsInfo:
    """The first weights trained for ``scene`` and exactly the parameter set ``params``."""
    want = tuple(sorted(params))
    found = available()
    for w in found:
        if w.scene == scene and tuple(sorted(w.params)) == want:
            return w
    have = ", ".join(f"{w.scene}[{'+'.join(w.params)}]" for w in found) or "none"
    raise PhysbenchError(
        f"no resnet3d weights for scene {scene!r} with parameters {'+'.join(want)}; available: "
        f"{have}. "
        f"Train them with `physbench train --scene {scene} --params {','.join(want)}` "
        "and put the output folder on PHYSBENCH_WEIGHTS."
    )
