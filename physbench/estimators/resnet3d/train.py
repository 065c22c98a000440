"""Training loop for the correction network: on-the-fly pairs, Adam on the MSE of the normalised
Δp, periodic atomic checkpoints (safetensors, no pickle) and resume."""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from physbench.errors import PhysbenchError
from physbench.estimators.resnet3d import weights
from physbench.estimators.resnet3d.network import NetConfig, build_net
from physbench.estimators.resnet3d.training_data import DataSpec, stream, validation_set

# The largest training run accepted: a typo (1e12 samples, a batch of a million) fails here,
# not hours later. 1e9 samples is 25,000 times the default budget; a batch of 4096 sequences of
# 64 frames x 512 px is already more activations than a GPU holds; 64 data processes is more than
# the cores of any one machine this runs on.
#: ``samples`` accepted: [1, this].
MAX_SAMPLES = 10**9
#: ``batch`` accepted: [1, this].
MAX_BATCH = 4096
#: ``workers`` accepted: [0, this] (0: data made in the training process).
MAX_WORKERS = 64


@dataclass(frozen=True)
class TrainConfig:
    samples: int = 40_000  # training budget, in samples
    batch: int = 16
    lr: float = 1e-3
    weight_decay: float = 1e-5
    val_groups: int = 24
    eval_every: int = 2_000  # samples between validation + checkpoint
    workers: int = 1  # data processes beside the training process
    threads: int = 0  # torch threads; 0 = torch's default
    seed: int = 0
    device: str = "cpu"  # "cuda" trains on a GPU; the weights are the same either way
    # Wall-clock budget of this session (0 = none); training stops at whichever budget ends first.
    minutes: float = 0.0
    # Start from these weights (fine-tuning) instead of a fresh network. Their widths, blocks,
    # dropout and outputs must be this network's; resolution and frames may differ (convolutions
    # and a global average pool: the same tensors take any input size). Training then draws its
    # scene instances after the ones those weights were trained on.
    init: str = ""

    def __post_init__(self) -> None:
        for name, low, high in (
            ("samples", 1, MAX_SAMPLES),
            ("batch", 1, MAX_BATCH),
            ("workers", 0, MAX_WORKERS),
        ):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= high:
                raise PhysbenchError(f"{name} = {v!r}: expected a whole number in [{low}, {high}]")


def progress_fraction(cfg: TrainConfig, seen: int, wall_s: float) -> float:
    """How much of the budget is spent: samples seen, or wall time when ``cfg.minutes`` is set and
    further along."""
    frac = seen / cfg.samples
    if cfg.minutes > 0:
        frac = max(frac, wall_s / (60.0 * cfg.minutes))
    return min(1.0, frac)


def learning_rate(cfg: TrainConfig, seen: int, wall_s: float = 0.0) -> float:
    """Linear warm-up over the first 5% of the budget, then cosine decay to 5% of ``cfg.lr``.

    A function of the budget spent only (samples, or wall time with ``cfg.minutes``), so a resumed
    run (even with a larger budget) needs no scheduler state.
    """
    import math

    frac = progress_fraction(cfg, seen, wall_s)
    warm = 0.05
    if frac < warm:
        return cfg.lr * max(frac, cfg.batch / cfg.samples) / warm
    frac = (frac - warm) / (1 - warm)
    return cfg.lr * (0.05 + 0.95 * 0.5 * (1 + math.cos(math.pi * frac)))


def weights_name(spec: DataSpec) -> str:
    """``SCENE__PARAMS``, SCENE the scene's name (a file's ``name``, not its path)."""
    return f"{spec.instance(0).name}__{'+'.join(sorted(spec.params))}"


def _ranges(spec: DataSpec) -> dict[str, list[float]]:
    from physbench.unknowns import ParamSpace

    space = ParamSpace.from_scene(spec.instance(0), spec.params)
    return {u.name: [u.low, u.high] for u in space.unknowns}


def init_groups(meta: dict[str, Any]) -> int:
    """Training groups to skip when fine-tuning from weights whose sidecar is ``meta``: those
    weights' own training drew groups from the start, one group per sample seen at most (a group
    holds many samples), plus the groups their own ``--init`` skipped; 0 where the sidecar does
    not say."""
    t = meta.get("training")
    if not isinstance(t, dict):
        return 0
    n = 0
    for key in ("first_group", "samples_seen"):
        v = t.get(key, 0)
        if isinstance(v, int) and not isinstance(v, bool) and v > 0:
            n += v
    return n


def _init(path: str, net: Any, net_cfg: NetConfig, load: bool) -> int:
    """``--init``: check that the weights at ``path`` fit ``net_cfg`` (only the input's resolution
    and frames may differ), load them into ``net`` where ``load`` (not when a checkpoint will
    replace them), and return the first training group (:func:`init_groups`)."""
    state, meta = weights.load(path)
    same_input = {"resolution": net_cfg.resolution, "frames": net_cfg.frames}
    if replace(NetConfig.from_dict(meta["net"]), **same_input) != net_cfg:
        raise PhysbenchError(
            f"--init {path!r} has architecture {meta['net']}, expected {net_cfg.to_dict()} "
            "(only resolution and frames may differ)"
        )
    if load:
        net.load_state_dict({k: v.float() for k, v in state.items()})
    return init_groups(meta)


def _starting_point(
    net: Any, vx: np.ndarray, vy: np.ndarray, out: Path, history: list[dict[str, Any]]
) -> float:
    """A fine-tune's starting point on this run's validation set: its curve's origin, and the best
    so far (saved as such), so that a fine-tune that only gets worse keeps the weights it started
    from. Returns that validation error."""
    val = evaluate_net(net, vx, vy)
    history.append({"samples": 0, "train_loss": None, "val_mse": val, "wall_s": 0.0})
    weights.save(out / "best.safetensors", dict(net.state_dict()), {"samples": 0, "val_mse": val})
    return val


def _optimizer_tensors(opt: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    sd = opt.state_dict()
    tensors = {f"opt.{i}.{k}": v for i, st in sd["state"].items() for k, v in st.items()}
    return tensors, {"param_groups": sd["param_groups"]}


def _load_optimizer(opt: Any, tensors: dict[str, Any], groups: dict[str, Any]) -> None:
    state: dict[int, dict[str, Any]] = {}
    for key, v in tensors.items():
        _, i, k = key.split(".", 2)
        state.setdefault(int(i), {})[k] = v
    opt.load_state_dict({"state": state, "param_groups": groups["param_groups"]})


def _pairs_dataset(spec: DataSpec, start: int) -> Any:
    """A torch ``IterableDataset`` over :func:`stream`, one disjoint seed stream per worker."""
    import torch

    class Pairs(torch.utils.data.IterableDataset):  # type: ignore[misc]
        def __iter__(self):  # type: ignore[no-untyped-def]
            info = torch.utils.data.get_worker_info()
            w, n = (info.id, info.num_workers) if info else (0, 1)
            for x, y in stream(spec, start, w, n):
                yield torch.from_numpy(x), torch.from_numpy(y)

    return Pairs()


def evaluate_net(net: Any, x: np.ndarray, y: np.ndarray, batch: int = 64) -> float:
    """Mean squared error of normalised Δp over a fixed set (dropout off, float32)."""
    import torch

    device = next(net.parameters()).device
    net.eval()
    err = 0.0
    with torch.no_grad():
        for i in range(0, len(x), batch):
            pred = net(torch.from_numpy(x[i : i + batch]).to(device)).float().cpu().numpy()
            err += float(((pred - y[i : i + batch]) ** 2).sum())
    net.train()
    return err / y.size


@dataclass
class _Session:
    """A training session's state: the net and optimiser on their device, and how far training
    got (samples seen, best validation MSE, learning curve, wall seconds of earlier sessions)."""

    net: Any
    opt: Any
    device: Any
    checkpoint: Path
    first_group: int = 0
    seen: int = 0
    best: float = float("inf")
    history: list[dict[str, Any]] = field(default_factory=list)
    wall0: float = 0.0


def _start(net_cfg: NetConfig, cfg: TrainConfig, out: Path, resume: bool) -> _Session:
    """The net and optimiser, from ``cfg.init`` weights or a checkpoint in ``out`` when resuming
    (its optimiser state, samples, curve and time included)."""
    import torch

    if cfg.threads:
        torch.set_num_threads(cfg.threads)
    torch.manual_seed(cfg.seed)
    device = torch.device(cfg.device)
    if device.type == "cuda":
        torch.backends.cudnn.benchmark = True
    net = build_net(net_cfg).to(device)
    opt = torch.optim.AdamW(net.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    s = _Session(net, opt, device, out / "checkpoint.safetensors")
    resuming = resume and s.checkpoint.is_file()
    # Training groups start here: after the groups the --init weights saw.
    s.first_group = _init(cfg.init, net, net_cfg, not resuming) if cfg.init else 0
    if resuming:
        tensors, meta = weights.read(s.checkpoint)
        net.load_state_dict({k[4:]: v for k, v in tensors.items() if k.startswith("net.")})
        _load_optimizer(
            opt, {k: v for k, v in tensors.items() if k.startswith("opt.")}, meta["optimizer"]
        )
        s.seen, s.best, s.history, s.wall0 = (
            meta["samples"],
            meta["best_val"],
            meta["history"],
            meta["wall_s"],
        )
    return s


def _save_checkpoint(s: _Session, out: Path, val: float, ema: float, wall: float) -> None:
    """Record a validation point on the curve, keep the best weights, write the checkpoint."""
    s.history.append(
        {"samples": s.seen, "train_loss": ema, "val_mse": val, "wall_s": round(wall, 1)}
    )
    if val < s.best:
        s.best = val
        weights.save(
            out / "best.safetensors", dict(s.net.state_dict()), {"samples": s.seen, "val_mse": val}
        )
    tensors, groups = _optimizer_tensors(s.opt)
    weights.save(
        s.checkpoint,
        {**{f"net.{k}": v for k, v in s.net.state_dict().items()}, **tensors},
        {
            "samples": s.seen,
            "best_val": s.best,
            "history": s.history,
            "wall_s": wall,
            "optimizer": groups,
        },
    )


def _optimise(
    s: _Session,
    spec: DataSpec,
    cfg: TrainConfig,
    validation: tuple[np.ndarray, np.ndarray],
    out: Path,
    progress: bool,
) -> None:
    """Train until :func:`progress_fraction` reaches 1, validating and checkpointing every
    ``cfg.eval_every`` samples and at the end."""
    import torch
    from tqdm import tqdm

    loader = torch.utils.data.DataLoader(
        _pairs_dataset(spec, s.first_group + s.seen),
        batch_size=cfg.batch,
        num_workers=cfg.workers,
        persistent_workers=cfg.workers > 0,
        prefetch_factor=4 if cfg.workers else None,
        pin_memory=s.device.type == "cuda",
    )
    bar = tqdm(
        total=cfg.samples, initial=s.seen, disable=not progress, unit="sample", dynamic_ncols=True
    )
    t0, ema, next_eval = time.perf_counter(), 0.0, s.seen + cfg.eval_every
    s.net.train()
    it = iter(loader)
    first = True
    while progress_fraction(cfg, s.seen, s.wall0 + time.perf_counter() - t0) < 1.0:
        x, y = next(it)
        x, y = x.to(s.device, non_blocking=True), y.to(s.device, non_blocking=True)
        for group in s.opt.param_groups:
            group["lr"] = learning_rate(cfg, s.seen, s.wall0 + time.perf_counter() - t0)
        loss = torch.nn.functional.mse_loss(s.net(x), y)
        s.opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(s.net.parameters(), 1.0)
        s.opt.step()
        s.seen += len(x)
        ema = loss.item() if first else 0.98 * ema + 0.02 * loss.item()
        first = False
        bar.update(len(x))
        wall = s.wall0 + time.perf_counter() - t0
        if s.seen >= next_eval or progress_fraction(cfg, s.seen, wall) >= 1.0:
            next_eval += cfg.eval_every
            val = evaluate_net(s.net, *validation)
            _save_checkpoint(s, out, val, ema, s.wall0 + time.perf_counter() - t0)
        rate = bar.format_dict.get("rate") or 0
        bar.set_postfix(loss=f"{ema:.4f}", val=f"{s.best:.4f}", rate=f"{rate:.0f}/s")
    bar.close()


def _sidecar(s: _Session, spec: DataSpec, net_cfg: NetConfig, cfg: TrainConfig) -> dict[str, Any]:
    """What the shipped weights record: the data, the net, the ranges, the training run."""
    import torch

    import physbench

    return {
        "scene": spec.instance(0).name,  # what the estimator looks weights up by
        "data": spec.to_dict(),
        "net": net_cfg.to_dict(),
        "ranges": _ranges(spec),
        "normalization": "target = (p_observed - p_simulated) / (high - low), per parameter of "
        "the marked body",
        "training": {
            **asdict(cfg),
            "first_group": s.first_group,
            "samples_seen": s.seen,
            "wall_s": round(s.history[-1]["wall_s"], 1) if s.history else 0.0,
        },
        "val_mse": s.best,
        "history": s.history,
        "physbench_version": physbench.__version__,
        "torch_version": torch.__version__,
    }


def train(
    spec: DataSpec,
    net_cfg: NetConfig,
    cfg: TrainConfig,
    out: str | Path,
    *,
    resume: bool = True,
    progress: bool = True,
) -> tuple[Path, dict[str, Any]]:
    """Train (or resume) into ``out``; returns the final weights path and its sidecar."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    s = _start(net_cfg, cfg, out, resume)
    if cfg.minutes > 0 and s.wall0 > 0:
        # ``minutes`` is this session's budget: the time horizon of the schedule ends that long
        # after what earlier sessions spent (their time counted against it, a resumed run with
        # --minutes 10 after 10 minutes stopped at once).
        cfg = replace(cfg, minutes=cfg.minutes + s.wall0 / 60.0)
    vx, vy = validation_set(spec, cfg.val_groups)
    if cfg.init and s.seen == 0:
        s.best = _starting_point(s.net, vx, vy, out, s.history)
    _optimise(s, spec, cfg, (vx, vy), out, progress)
    best_state, _ = weights.read(out / "best.safetensors")
    meta = _sidecar(s, spec, net_cfg, cfg)
    # Shipped weights are int8 per output channel (a quarter of the size; loading dequantises).
    final = weights.save(
        out / weights_name(spec), weights.quantize(best_state), {**meta, "storage": weights.INT8}
    )
    (out / "train_log.json").write_text(json.dumps(s.history, indent=1))
    return final, meta
