"""Training-data scaling: resnet3d training pairs per second against data workers, next to the raw
engine's episodes per second with as many processes, in the same run.

    python benchmarks/datagen_scaling.py [--workers 1 2] [--repeats 3] [--seconds 6]
        [--scene three_circles] [--params mass] [--out results/datagen_scaling]

Pairs: the data pipeline of ``physbench train`` (``--workers N``): the same torch ``DataLoader``
over :func:`physbench.estimators.resnet3d.training_data.stream` with ``N`` worker processes,
batches of 32 and the shipped models' blur augmentation (``--blur-max 4``, as in
``benchmarks/train_resnet3d.py``), drained by a main process that does no training, so the
workers have the cores to themselves. After a warm-up (every worker's first batches: process
start, imports, the first groups), pairs per second over ``--seconds``.

Raw engine: ``simulate`` only (no render, no pairs) of the same scene instances with random
parameters, over a warmed pool of ``N`` processes: the ceiling the pairs could scale by.

The worker counts alternate in order each repeat; medians. Writes ``OUT/datagen_scaling.json``
(every run and the load average) and ``OUT/datagen_scaling.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any

BATCH = 32
BLUR_MAX = 4.0


def data_spec(scene: str, params: str) -> Any:
    from physbench.estimators.resnet3d.training_data import DataSpec

    return DataSpec(scene, tuple(params.split(",")), blur_max=BLUR_MAX)


def pairs_per_second(spec: Any, workers: int, seconds: float) -> float:
    """Training pairs per second from ``physbench train``'s data loader with ``workers``."""
    import torch

    from physbench.estimators.resnet3d.train import _pairs_dataset

    loader = torch.utils.data.DataLoader(
        _pairs_dataset(spec, 0),
        batch_size=BATCH,
        num_workers=workers,
        persistent_workers=True,
        prefetch_factor=4,
    )
    it = iter(loader)
    try:
        for _ in range(2 * workers):  # each worker started and made its first groups
            next(it)
        n, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            n += len(next(it)[1])
        return n / (time.perf_counter() - t0)
    finally:
        del it  # stops the workers


def simulate_groups(item: tuple[str, str, int, int]) -> int:
    """Runs in a pool process: ``n`` simulations of training instance ``seed``, random
    parameters, ``simulate`` only; returns how many succeeded."""
    import numpy as np

    from physbench.components import create
    from physbench.errors import SimulationError
    from physbench.estimators.resnet3d.training_data import TRAIN_SEED0
    from physbench.unknowns import ParamSpace

    scene_name, params, seed, n = item
    spec = data_spec(scene_name, params)
    scene = spec.instance(TRAIN_SEED0 + seed)
    space = ParamSpace.from_scene(scene, spec.params)
    sim = create("simulator", spec.engine)
    rng = np.random.default_rng(seed)
    done = 0
    for _ in range(n):
        try:
            sim.simulate(scene, space.sample(rng))
            done += 1
        except SimulationError:
            pass
    return done


def episodes_per_second(scene: str, params: str, workers: int, seconds: float) -> float:
    """Raw engine episodes per second over a warmed pool of ``workers`` processes, for about
    ``seconds``."""
    import multiprocessing

    # a task: one instance's simulations for 8 groups, so that the pool's round trips stay small
    group = 8 * data_spec(scene, params).group
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        pool.map(simulate_groups, [(scene, params, g, group) for g in range(2 * workers)])
        n, g, t0 = 0, 2 * workers, time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            items = [(scene, params, g + k, group) for k in range(4 * workers)]
            n += sum(pool.map(simulate_groups, items, chunksize=1))
            g += len(items)
        return n / (time.perf_counter() - t0)


def summarise(runs: dict[int, list[float]]) -> dict[str, Any]:
    """Per worker count: every run and the median; ``speedup``: median / the 1-worker median."""
    base = statistics.median(runs[min(runs)])
    return {
        str(w): {
            "runs": [round(x, 1) for x in rs],
            "median": round(statistics.median(rs), 1),
            "speedup": round(statistics.median(rs) / base, 3),
        }
        for w, rs in runs.items()
    }


def markdown(result: dict[str, Any]) -> str:
    pairs, eps = result["pairs_per_s"], result["episodes_per_s"]
    lines = [
        "# Training-data scaling (resnet3d)",
        "",
        f"Machine: {result['machine']}. Scene `{result['scene']}`, unknowns `{result['params']}`, "
        f"batches of {BATCH}, blur augmentation up to {BLUR_MAX:g} px; {result['repeats']} repeats "
        f"of {result['seconds']:g} s per worker count (alternating), medians; "
        "`python benchmarks/datagen_scaling.py`. Load average (1 min) at each repeat: "
        + ", ".join(f"{x:.1f}" for x in result["load"])
        + ".",
        "",
        "| workers | pairs/s | speed-up | raw engine episodes/s | speed-up (ceiling) | "
        "pairs/s runs | episodes/s runs |",
        "|---|---|---|---|---|---|---|",
    ]
    for w in pairs:
        p, e = pairs[w], eps[w]
        lines.append(
            f"| {w} | {p['median']:.0f} | {p['speedup']:.2f} | {e['median']:.0f} | "
            f"{e['speedup']:.2f} | {' '.join(f'{x:.0f}' for x in p['runs'])} | "
            f"{' '.join(f'{x:.0f}' for x in e['runs'])} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=6.0)
    ap.add_argument("--scene", default="three_circles")
    ap.add_argument("--params", default="mass")
    ap.add_argument("--out", default="results/datagen_scaling")
    args = ap.parse_args()
    if min(args.workers) < 1:
        sys.exit(f"--workers {args.workers}: expected whole numbers >= 1")
    workers = sorted(set(args.workers))
    spec = data_spec(args.scene, args.params)
    pairs: dict[int, list[float]] = {w: [] for w in workers}
    eps: dict[int, list[float]] = {w: [] for w in workers}
    load = []
    for r in range(args.repeats):
        load.append(os.getloadavg()[0])
        for w in workers if r % 2 == 0 else workers[::-1]:
            pairs[w].append(pairs_per_second(spec, w, args.seconds))
            eps[w].append(episodes_per_second(args.scene, args.params, w, args.seconds))
            print(
                f"repeat {r + 1}/{args.repeats}, {w} worker(s): {pairs[w][-1]:.0f} pairs/s, "
                f"{eps[w][-1]:.0f} episodes/s, load {os.getloadavg()[0]:.1f}",
                file=sys.stderr,
            )
    result = {
        "machine": f"{os.cpu_count()} cores",
        "python": platform.python_version(),
        "scene": args.scene,
        "params": args.params,
        "repeats": args.repeats,
        "seconds": args.seconds,
        "load": load,
        "pairs_per_s": summarise(pairs),
        "episodes_per_s": summarise(eps),
    }
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "datagen_scaling.json").write_text(json.dumps(result, indent=1) + "\n")
    (out / "datagen_scaling.md").write_text(markdown(result))
    print(markdown(result))


if __name__ == "__main__":
    main()
