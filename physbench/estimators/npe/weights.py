"""npe weights: safetensors plus a JSON sidecar with the tensors' SHA-256, written and read by
resnet3d's :mod:`~physbench.estimators.resnet3d.weights` (never unpickled). All ensemble members
live in one file, member ``i``'s tensors prefixed ``m{i}.``. Shipped weights live in
``physbench/estimators/npe/weights/``; ``PHYSBENCH_NPE_WEIGHTS`` (a path list) adds folders
searched first (a separate variable: resnet3d would warn about every npe sidecar in its folders).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from physbench.errors import PhysbenchError
from physbench.estimators.resnet3d.weights import read, read_sidecar, save

__all__ = ["SHIPPED", "find", "load", "save"]

SHIPPED = Path(__file__).with_name("weights")


def search_dirs() -> list[Path]:
    extra = [Path(p) for p in os.environ.get("PHYSBENCH_NPE_WEIGHTS", "").split(os.pathsep) if p]
    return [*extra, SHIPPED]


def find(scene: str, params: tuple[str, ...]) -> Path:
    """The first npe weights trained for ``scene`` and exactly the unknowns ``params``; called by
    the estimator's start when no ``weights`` option names a file."""
    want = sorted(params)
    have = []
    for d in search_dirs():
        for side in sorted(d.glob("*.json")) if d.is_dir() else []:
            try:
                meta = read_sidecar(side)
            except PhysbenchError:
                continue
            if meta.get("kind") != "npe" or not side.with_suffix(".safetensors").is_file():
                continue
            trained = meta.get("data", {})
            have.append(f"{trained.get('scene')}[{'+'.join(trained.get('params', []))}]")
            if trained.get("scene") == scene and sorted(trained.get("params", [])) == want:
                return side.with_suffix(".safetensors")
    raise PhysbenchError(
        f"no npe weights for scene {scene!r} with parameters {'+'.join(want)}; available: "
        f"{', '.join(have) or 'none'}. Train them with `physbench train --posterior --scene "
        f"{scene} --params {','.join(want)}` and put the output folder on PHYSBENCH_NPE_WEIGHTS."
    )


def load(path: str | Path) -> tuple[list[Any], dict[str, Any]]:
    """The ensemble members (torch modules, eval mode) and the sidecar of ``path``, checked: an
    npe sidecar, and tensors that are exactly the members its ``net`` describes."""
    from physbench.estimators.npe.network import MDNConfig, build_mdn

    tensors, meta = read(path)
    where = f"npe weights {str(path)!r}"
    if meta.get("kind") != "npe" or not isinstance(meta.get("net"), dict):
        raise PhysbenchError(
            f"{where}: the sidecar's kind is {meta.get('kind')!r}, expected 'npe' with a net "
            "(resnet3d weights go to -e resnet3d)"
        )
    cfg = MDNConfig.from_dict(meta["net"])
    out = []
    for i in range(cfg.members):
        member = build_mdn(cfg)
        prefix = f"m{i}."
        state = {k[len(prefix) :]: v for k, v in tensors.items() if k.startswith(prefix)}
        want = {k: tuple(v.shape) for k, v in member.state_dict().items()}
        got = {k: tuple(v.shape) for k, v in state.items()}
        if got != want:
            raise PhysbenchError(
                f"{where}: member {i}'s tensors {sorted(got)[:4]} do not fit the sidecar's net "
                f"{meta['net']}"
            )
        member.load_state_dict({k: v.float() for k, v in state.items()})
        out.append(member.eval())
    return out, meta
