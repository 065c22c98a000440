"""Training the npe ensemble by maximum likelihood: simulate, summarize, fit each member with
early stopping on a held-out validation set, save them together.

Simulations are the cost (3-11 ms each here); the features they give are cached in the output
folder (``pairs.npz``), so a rerun with other network settings simulates nothing.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from physbench.estimators.npe.features import domain_record
from physbench.estimators.npe.network import MDNConfig, build_mdn, ensemble_log_prob, to_logit
from physbench.estimators.npe.training_data import (
    TRAIN_SEED0,
    VAL_SEED0,
    NPEDataSpec,
    simulate_pairs,
)


@dataclass(frozen=True)
class NPETrainConfig:
    """``samples``: training simulations (validation: a tenth as many more)."""

    samples: int = 20_000
    batch: int = 256
    lr: float = 1e-3
    weight_decay: float = 1e-5
    max_epochs: int = 300
    patience: int = 25
    seed: int = 0
    threads: int = 0


def weights_name(spec: NPEDataSpec) -> str:
    return f"{spec.scene}__{'+'.join(sorted(spec.params))}"


def _pairs(spec: NPEDataSpec, cfg: NPETrainConfig, out: Path) -> tuple[np.ndarray, ...]:
    cache = out / "pairs.npz"
    key = json.dumps([spec.to_dict(), cfg.samples], sort_keys=True)
    if cache.is_file():
        with np.load(cache) as f:
            if str(f["key"]) == key:
                return f["x"], f["y"], f["vx"], f["vy"]
    x, y = simulate_pairs(spec, range(TRAIN_SEED0, TRAIN_SEED0 + cfg.samples))
    vx, vy = simulate_pairs(spec, range(VAL_SEED0, VAL_SEED0 + max(cfg.samples // 10, 2)))
    np.savez(cache, x=x, y=y, vx=vx, vy=vy, key=np.array(key))
    return x, y, vx, vy


def _fit(member: Any, x: Any, z: Any, vx: Any, vz: Any, cfg: NPETrainConfig, seed: int) -> dict:
    """Adam on the negative log-likelihood; keeps the state of the best validation epoch."""
    import torch

    gen = torch.Generator().manual_seed(seed)
    opt = torch.optim.AdamW(member.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    sched = torch.optim.lr_scheduler.ReduceLROnPlateau(opt, factor=0.5, patience=cfg.patience // 3)
    best, best_state, since, history = float("inf"), None, 0, []
    for _ in range(cfg.max_epochs):
        member.train()
        perm = torch.randperm(len(x), generator=gen)
        for i in range(0, len(x), cfg.batch):
            idx = perm[i : i + cfg.batch]
            loss = -member.log_prob(x[idx], z[idx]).mean()
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(member.parameters(), 5.0)
            opt.step()
        member.eval()
        with torch.no_grad():
            val = float(-member.log_prob(vx, vz).mean())
        sched.step(val)
        history.append(round(val, 4))
        if val < best - 1e-4:
            best, since = val, 0
            best_state = {k: v.clone() for k, v in member.state_dict().items()}
        else:
            since += 1
            if since >= cfg.patience:
                break
    member.load_state_dict(best_state)
    return {"val_nll": best, "epochs": len(history), "val_history": history}


def train(
    spec: NPEDataSpec,
    net: MDNConfig | None,
    cfg: NPETrainConfig,
    out: str | Path,
    *,
    progress: bool = True,
) -> tuple[Path, dict[str, Any]]:
    """Train into ``out``; returns the weights path and its sidecar. ``net``: the architecture
    (its ``n_features``/``n_params`` are set from the data; ``None``: the defaults)."""
    import sys

    import torch

    import physbench
    from physbench.estimators.npe import weights
    from physbench.unknowns import ParamSpace

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if cfg.threads:
        torch.set_num_threads(cfg.threads)
    t0 = time.perf_counter()
    x, y, vx, vy = _pairs(spec, cfg, out)
    sim_s = time.perf_counter() - t0
    base = net or MDNConfig(n_features=0, n_params=0)
    net = MDNConfig(**{**base.to_dict(), "n_features": x.shape[1], "n_params": y.shape[1]})
    mean = torch.from_numpy(x.mean(axis=0))
    std = torch.from_numpy(x.std(axis=0)).clamp_min(1e-6)
    tx, tz = torch.from_numpy(x), torch.from_numpy(to_logit(y).astype(np.float32))
    tvx, tvz = torch.from_numpy(vx), torch.from_numpy(to_logit(vy).astype(np.float32))
    members, records = [], []
    for m in range(net.members):
        torch.manual_seed(cfg.seed * 1000 + m)
        member = build_mdn(net)
        member.feature_mean.copy_(mean)
        member.feature_std.copy_(std)
        records.append(_fit(member, tx, tz, tvx, tvz, cfg, cfg.seed * 1000 + m))
        members.append(member.eval())
        if progress:
            r = records[-1]
            print(
                f"member {m}: validation NLL {r['val_nll']:.3f} after {r['epochs']} epochs",
                file=sys.stderr,
            )
    with torch.no_grad():
        val_nll = float(-ensemble_log_prob(members, tvx, tvz).mean())
    domain = domain_record(vx, mean.numpy(), std.numpy())
    space = ParamSpace.from_scene(spec.instance(0), spec.params)
    meta = {
        "kind": "npe",
        "scene": spec.scene,
        "data": spec.to_dict(),
        "net": net.to_dict(),
        "ranges": {u.name: [u.low, u.high] for u in space.unknowns},
        "embedding": "pixel summaries (physbench.estimators.npe.features), not a 3D-ResNet",
        "density": "equal-weight ensemble of mixture density networks over logit(unit) values",
        "training": {
            **asdict(cfg),
            "train_rows": len(x),
            "val_rows": len(vx),
            "simulate_s": round(sim_s, 1),
            "wall_s": round(time.perf_counter() - t0, 1),
            "members": records,
        },
        "val_nll": val_nll,
        "domain": domain,
        "physbench_version": physbench.__version__,
        "torch_version": torch.__version__,
    }
    state = {f"m{i}.{k}": v for i, mem in enumerate(members) for k, v in mem.state_dict().items()}
    path = weights.save(out / weights_name(spec), state, meta)
    return path, meta
