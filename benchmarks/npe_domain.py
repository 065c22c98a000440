"""Add the training-domain record to npe weights trained before training wrote it.

npe says "outside npe's training data" when an observation's summary features lie farther from
the training set than :data:`~physbench.estimators.npe.features.DOMAIN_FACTOR` times the farthest
validation case (:func:`~physbench.estimators.npe.features.domain_record`). Training writes the
record into the weights' sidecar; for weights trained before, this script recomputes it exactly
as training would have: the validation set is simulated again with the generator and seeds the
sidecar records (``simulate_pairs`` on seeds ``VAL_SEED0 .. VAL_SEED0 + samples // 10``, the
sidecar's scene, unknowns, engine and renderer), and the distances use the feature mean and
spread stored in the weights. Only the sidecar's JSON changes: the tensors and their SHA-256 stay.
CPU only, about 2-5 minutes per row on an idle core.

    python benchmarks/npe_domain.py [--write] [WEIGHTS.safetensors ...]   # default: the shipped
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from physbench.estimators.npe import weights
from physbench.estimators.npe.features import domain_record
from physbench.estimators.npe.training_data import VAL_SEED0, NPEDataSpec, simulate_pairs


def record(path: Path) -> dict[str, object]:
    """The domain record of the weights at ``path``, from their recorded validation set."""
    members, meta = weights.load(path)
    spec = NPEDataSpec.from_dict(meta["data"])
    samples = int(meta["training"]["samples"])
    vx, _ = simulate_pairs(spec, range(VAL_SEED0, VAL_SEED0 + max(samples // 10, 2)))
    if len(vx) != meta["training"]["val_rows"]:
        raise SystemExit(
            f"{path}: {len(vx)} validation rows, the sidecar records {meta['training']['val_rows']}"
        )
    mean = members[0].feature_mean.double().numpy()
    std = members[0].feature_std.double().numpy()
    return domain_record(vx, mean, std)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("paths", nargs="*", type=Path)
    p.add_argument("--write", action="store_true", help="write the record into each sidecar")
    args = p.parse_args()
    paths = args.paths or sorted(weights.SHIPPED.glob("*.safetensors"))
    for path in paths:
        rec = record(path)
        print(path.name, json.dumps(rec), flush=True)
        if args.write:
            side = path.with_suffix(".json")
            meta = json.loads(side.read_text())
            meta["domain"] = rec
            side.write_text(json.dumps(meta, indent=2, sort_keys=True))  # as weights.save writes it


if __name__ == "__main__":
    main()
