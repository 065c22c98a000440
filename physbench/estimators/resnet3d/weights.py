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
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from physbench.errors import PhysbenchError

SHIPPED = Path(__file__).with_name("weights")
#: Sidecar ``storage`` value of weights kept as int8 with one float32 scale per output channel.
INT8 = "int8-per-output-channel"
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


def load(path: str | Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """(tensors, meta) from a .safetensors file and its sidecar; int8 storage comes back as
    float32. A sidecar whose ``sha256`` is not the tensors' is refused."""
    from safetensors.torch import load as decode

    path = Path(path).with_suffix(".safetensors")
    side = path.with_suffix(".json")
    if not path.is_file() or not side.is_file():
        raise PhysbenchError(f"weights {str(path)!r} need both {path.name} and {side.name}")
    data, meta = path.read_bytes(), json.loads(side.read_text())
    digest = meta.get("sha256")
    if digest is not None and hashlib.sha256(data).hexdigest() != digest:
        raise PhysbenchError(
            f"weights {str(path)!r}: {side.name} describes other tensors (its sha256 "
            f"{str(digest)[:12]}… is not the file's): the pair comes from two saves, e.g. an "
            "interrupted one; save or train again"
        )
    tensors = decode(data)
    if meta.get("storage") == INT8:
        tensors = dequantize(tensors)
    return tensors, meta


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


def dequantize(tensors: dict[str, Any]) -> dict[str, Any]:
    """Float32 tensors back from :func:`quantize`'s output."""
    out: dict[str, Any] = {}
    for name, t in tensors.items():
        if name.endswith(_SCALE):
            continue
        scale = tensors.get(name + _SCALE)
        if scale is None:
            out[name] = t.float()
        else:
            out[name] = t.float() * scale.float().view((-1,) + (1,) * (t.dim() - 1))
    return out


def search_dirs() -> list[Path]:
    extra = [Path(p) for p in os.environ.get("PHYSBENCH_WEIGHTS", "").split(os.pathsep) if p]
    return [*extra, SHIPPED]


def available() -> list[WeightsInfo]:
    """Every weights file found, searched folders first to last."""
    out = []
    for d in search_dirs():
        for side in sorted(d.glob("*.json")) if d.is_dir() else []:
            st = side.with_suffix(".safetensors")
            if st.is_file():
                out.append(WeightsInfo(st, json.loads(side.read_text())))
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
