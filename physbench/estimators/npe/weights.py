"""npe weights: safetensors plus a JSON sidecar with the tensors' SHA-256, written and read by
resnet3d's :mod:`~physbench.estimators.resnet3d.weights` (never unpickled). All ensemble members
live in one file, member ``i``'s tensors prefixed ``m{i}.``. Shipped weights live in
``physbench/estimators/npe/weights/``; ``PHYSBENCH_NPE_WEIGHTS`` (a path list) adds folders
searched first (a separate variable: resnet3d would warn about every npe sidecar in its folders).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from physbench.errors import PhysbenchError
from physbench.estimators.resnet3d.weights import (
    empty_folder,
    named_dirs,
    read,
    read_sidecar,
    save,
)

__all__ = ["SHIPPED", "find", "load", "save"]

SHIPPED = Path(__file__).with_name("weights")


def search_dirs() -> list[Path]:
    return [*named_dirs("PHYSBENCH_NPE_WEIGHTS"), SHIPPED]


def find(scene: str, params: tuple[str, ...]) -> Path:
    """The first npe weights trained for ``scene`` and exactly the unknowns ``params``; called by
    the estimator's start when no ``weights`` option names a file. A ``PHYSBENCH_NPE_WEIGHTS``
    folder without any npe weights is an error, not a silent fall-back to the shipped ones."""
    want = sorted(params)
    named = named_dirs("PHYSBENCH_NPE_WEIGHTS")
    found: list[tuple[Path, dict[str, Any]]] = []
    for d in [*named, SHIPPED]:
        here, skipped = _scan(d)
        if not here and d in named:
            raise empty_folder(
                "PHYSBENCH_NPE_WEIGHTS", d, "npe", skipped, "physbench train --posterior"
            )
        found += here
    have = []
    for path, trained in found:
        have.append(f"{trained.get('scene')}[{'+'.join(trained.get('params', []))}]")
        if trained.get("scene") == scene and sorted(trained.get("params", [])) == want:
            return path
    raise PhysbenchError(
        f"no npe weights for scene {scene!r} with parameters {'+'.join(want)}; available: "
        f"{', '.join(have) or 'none'}. Train them with `physbench train --posterior --scene "
        f"{scene} --params {','.join(want)}` and put the output folder on PHYSBENCH_NPE_WEIGHTS."
    )


def _scan(folder: Path) -> tuple[list[tuple[Path, dict[str, Any]]], list[str]]:
    """The npe weights in ``folder`` (path, the sidecar's ``data``), and why each other pair
    there was passed over."""
    found, skipped = [], []
    for side in sorted(folder.glob("*.json")) if folder.is_dir() else []:
        st = side.with_suffix(".safetensors")
        if not st.is_file():
            continue
        try:
            meta = read_sidecar(side)
        except PhysbenchError as exc:
            skipped.append(f"{str(st)!r}: {exc}")
            continue
        if meta.get("kind") != "npe":
            skipped.append(f"{str(st)!r}: its sidecar's kind is {meta.get('kind')!r}, not 'npe'")
            continue
        trained = meta.get("data")
        found.append((st, trained if isinstance(trained, dict) else {}))
    return found, skipped


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
