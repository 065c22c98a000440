"""One shot on a GPU machine (issue 29, item 4): the two Table 1 rows whose 2-iteration error
misses the paper's NN after 11 (three_circles elasticity, bouncing_balls mass), fine-tuned from
the shipped weights for a fixed wall time, then every model evaluated after 2 iterations on the
same held-out seeds as the shipped one.

    bash benchmarks/gpu_oneshot.sh        # on the GPU machine (installs .whl/, writes into $OUT)
    python benchmarks/oneshot_gpu.py --out out/oneshot --device cpu --train-seconds 20 \\
        --seeds 3 --deadline 400           # a dry run on a CPU

Arms, per row, each its own ``physbench train`` process with as many data workers as the others:

* ``ft32``: the shipped weights fine-tuned at their own input (32 px, 15 frames), lr 3e-4, on
  scene instances they never saw ("more data at 32 px" and "fine-tuning" in one);
* ``in64``: the bigger input (64 px, all 30 frames), from the same tensors (the network is
  convolutions and a global average pool), lr 1e-3: at that input the shipped weights start as
  far off as a fresh network (validation MSE 0.2, a fresh net's 0.17), so it gets the from-scratch
  recipe's rate.

The training loss needs no variant aimed at the first step: a training pair already is the
loop's first correction (observed and simulated parameters two independent draws from the
ranges, as the truth and the random initial guess are; the loss is that correction's squared
error, normalised by the range). Everything else is the shipped recipe (batch 32, blur
augmentation up to 4 px on half the observations).

Timeline, in seconds after ``ONESHOT_T0`` (the wrapper's start; else this script's): the arms
train ``--train-seconds`` (their learning-rate schedules run over that wall time, which starts
after their start-up); an arm still running 90 s after that is killed and its best weights so
far are kept; then the evaluation runs on
every core, seed after seed (all weights of a seed before the next seed), until ``--deadline``;
seeds not finished for every weights file of a row by then are left out of that row.

Writes into ``--out``: ``results.json`` (per-seed errors, training curves, summary),
``summary.md``, and one ``weights_ROW.tar`` per row (each arm's int8 weights, sidecar, log and
training curve, under ``ARM/``).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import signal
import subprocess
import sys
import tarfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
#: (scene, params): the rows the one-shot table misses (results/resnet3d/table.md).
ROWS: list[tuple[str, str]] = [("three_circles", "elasticity"), ("bouncing_balls", "mass")]
#: Arm -> the ``physbench train`` options that make it (beside the shared ones in :func:`launch`).
ARMS: dict[str, list[str]] = {
    "ft32": ["--resolution", "32", "--frames", "15", "--lr", "3e-4"],
    "in64": ["--resolution", "64", "--frames", "30", "--lr", "1e-3"],
    # ft32 with half the simulations drawn near another's parameters: pairs aimed at the second
    # correction, which the first run's arms never trained on.
    "near32": ["--resolution", "32", "--frames", "15", "--lr", "3e-4", "--near", "0.5"],
}
BLURS = (0.0, 3.0)
#: An arm still running this long after its training budget began is killed (start-up included).
KILL_GRACE_S = 90.0
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))  # physbench from this checkout, here and in the pool's workers


def row_name(scene: str, params: str) -> str:
    return f"{scene}__{params}"


def paper(scene: str, params: str) -> float:
    """The paper's NN value after 11 iterations (the one-shot table's target)."""
    from physbench.bench.tables import paper_value

    value = paper_value(scene, params, "NN")
    assert value is not None, (scene, params)
    return value[0]


def shipped(scene: str, params: str) -> Path:
    return (
        REPO
        / "physbench"
        / "estimators"
        / "resnet3d"
        / "weights"
        / f"{scene}__{params}.safetensors"
    )


def ensure_entry_points(site: Path) -> None:
    """Where physbench is not installed (the GPU machine runs the bare checkout), write its
    entry points into ``site`` (:func:`write_entry_points`) and put that on the path, so the
    plugin registry finds the built-in components as an installed physbench would."""
    import importlib.metadata as md

    if md.entry_points(group="physbench"):
        return
    write_entry_points(site)
    sys.path.insert(0, str(site))
    os.environ["PYTHONPATH"] = os.pathsep.join(
        p for p in (str(site), os.environ.get("PYTHONPATH", "")) if p
    )


def write_entry_points(site: Path) -> Path:
    """A ``physbench-0.0.0.dist-info`` in ``site`` holding pyproject's entry points."""
    import tomllib

    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    info = site / "physbench-0.0.0.dist-info"
    info.mkdir(parents=True, exist_ok=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: physbench\nVersion: 0.0.0\n")
    eps = project["entry-points"]["physbench"]
    (info / "entry_points.txt").write_text(
        "[physbench]\n" + "".join(f"{k} = {v}\n" for k, v in eps.items())
    )
    return info


def launch(args: argparse.Namespace, runs: Path, workers: int) -> dict[str, Any]:
    procs = {}
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "PYTHONUNBUFFERED": "1"}
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), env.get("PYTHONPATH", "")) if p)
    for scene, params in ROWS:
        for arm in args.arms:
            out = runs / row_name(scene, params) / arm
            out.mkdir(parents=True, exist_ok=True)
            cmd = [
                sys.executable,
                "-m",
                "physbench",
                "train",
                "--scene",
                scene,
                "--params",
                params,
                "--init",
                str(shipped(scene, params)),
                *ARMS[arm],
                "--out",
                str(out),
                "--samples",
                "100000000",
                "--minutes",
                f"{args.train_seconds / 60:.4f}",
                "--device",
                args.device,
                "--workers",
                str(workers),
                "--threads",
                "1",
                "--batch",
                "32",
                "--blur-max",
                "4",
                "--val-groups",
                str(args.val_groups),
                "--eval-every",
                str(args.eval_every),
                "--eval-seeds",
                "0",
                "--no-resume",
                "--quiet",
            ]
            log = (out / "log.txt").open("w")
            log.write(" ".join(cmd[1:]) + "\n")
            log.flush()
            procs[f"{row_name(scene, params)}/{arm}"] = subprocess.Popen(
                cmd, stdout=log, stderr=subprocess.STDOUT, env=env, start_new_session=True
            )
    return procs


def wait(procs: dict[str, Any], until: float, t0: float) -> dict[str, Any]:
    """Exit codes by run; a run still going at ``until`` is killed (its process group: the data
    workers too) and gets ``"killed"``."""
    codes: dict[str, Any] = {}
    while len(codes) < len(procs) and time.time() < until:
        for key, p in procs.items():
            if key not in codes and p.poll() is not None:
                codes[key] = p.returncode
                print(f"[{time.time() - t0:5.0f} s] {key}: exit {p.returncode}", flush=True)
        time.sleep(1.0)
    for key, p in procs.items():
        if key in codes:
            continue
        for sig in (signal.SIGTERM, signal.SIGKILL):
            try:
                os.killpg(p.pid, sig)
            except ProcessLookupError:
                break
            try:
                p.wait(timeout=10)
                break
            except subprocess.TimeoutExpired:
                continue
        codes[key] = "killed"
        print(f"[{time.time() - t0:5.0f} s] {key}: killed at the deadline", flush=True)
    return codes


def final_weights(run: Path, scene: str, params: str) -> tuple[Path | None, str]:
    """The run's weights and how they came: ``finished``, or ``best so far`` (a killed run: its
    best checkpoint, int8, with the shipped sidecar's data and the run's own net and curve)."""
    name = row_name(scene, params)
    final = run / f"{name}.safetensors"
    if final.is_file() and final.with_suffix(".json").is_file():
        return final, "finished"
    best = run / "best.safetensors"
    if not best.is_file():
        return None, "no weights"
    from physbench.estimators.resnet3d import weights

    state, _ = weights.read(best)
    _, meta = weights.load(shipped(scene, params))
    log_cmd = (run / "log.txt").read_text().splitlines()[0].split()
    res, frames = (int(log_cmd[log_cmd.index(k) + 1]) for k in ("--resolution", "--frames"))
    ck = run / "checkpoint.json"
    saved = json.loads(ck.read_text()) if ck.is_file() else {}
    history = saved.get("history", [])
    meta = {
        **{k: v for k, v in meta.items() if k != "sha256"},
        "data": {**meta["data"], "resolution": res, "frames": frames},
        "net": {**meta["net"], "resolution": res, "frames": frames},
        "history": history,
        "val_mse": min((h["val_mse"] for h in history), default=math.nan),
        "training": {
            "unfinished": True,
            "samples_seen": saved.get("samples"),
            "wall_s": saved.get("wall_s"),
        },
        "storage": weights.INT8,
    }
    out = run / "partial" / f"{name}.safetensors"
    weights.save(out, weights.quantize(state), meta)
    return out, "best so far"


def _init_eval_worker() -> None:
    import torch

    torch.set_num_threads(1)


def _eval_cell(cell: tuple[str, str, str, float, int]) -> tuple[Any, ...]:
    """(cell, normalized min MSE after 2 iterations or None, error or None, seconds)."""
    from physbench.bench.held_out import evaluate_weights

    _, _, path, blur, seed = cell
    t = time.perf_counter()
    try:
        value = float(evaluate_weights(path, [seed], iterations=2, blur=blur)[0][2])
        return cell, value, None, time.perf_counter() - t
    except Exception as exc:  # one failed cell must not end the others
        return cell, None, f"{type(exc).__name__}: {exc}", time.perf_counter() - t


def evaluate(
    models: dict[str, dict[str, str]], seeds: int, until: float, t0: float, processes: int
) -> list[dict[str, Any]]:
    """Every (row, weights, blur) on seeds 0..seeds-1, seed-major, until the deadline."""
    import multiprocessing as mp

    cells = [
        (row, which, path, blur, seed)
        for seed in range(seeds)
        for row, paths in models.items()
        for which, path in paths.items()
        for blur in BLURS
    ]
    done: list[dict[str, Any]] = []
    if not cells or time.time() >= until:
        return done
    ctx = mp.get_context("spawn")  # the parent holds no torch or CUDA state a fork would copy
    pool = ctx.Pool(processes, initializer=_init_eval_worker)
    try:
        it = pool.imap_unordered(_eval_cell, cells, chunksize=1)
        for _ in cells:
            left = until - time.time()
            if left <= 0:
                break
            try:
                cell, value, error, secs = it.next(timeout=left)
            except mp.TimeoutError:
                break
            row, which, _, blur, seed = cell
            done.append(
                {
                    "row": row,
                    "weights": which,
                    "blur": blur,
                    "seed": seed,
                    "after_2": value,
                    "error": error,
                    "seconds": round(secs, 3),
                }
            )
            if len(done) % 100 == 0:
                print(f"[{time.time() - t0:5.0f} s] {len(done)}/{len(cells)} cells", flush=True)
    finally:
        pool.terminate()
        pool.join()
    return done


def summarize(
    cells: list[dict[str, Any]], models: dict[str, dict[str, str]]
) -> list[dict[str, Any]]:
    """Per row, blur and weights: the mean after 2 iterations on the seeds every weights file of
    the row finished, its 90 % BCa interval, the distance to the paper's value, and the paired
    ratio to the shipped weights."""
    try:
        from physbench.bench.tables import bootstrap_ci, ratio_ci
    except Exception:  # no intervals rather than no summary

        def bootstrap_ci(values: Any, **_: Any) -> tuple[float, float]:
            return math.nan, math.nan

        def ratio_ci(num: Any, den: Any, **_: Any) -> tuple[float, float, float]:
            return sum(num) / sum(den), math.nan, math.nan

    target = {row_name(s, p): paper(s, p) for s, p in ROWS}
    out = []
    for row, paths in models.items():
        for blur in BLURS:
            by: dict[str, dict[int, float]] = {w: {} for w in paths}
            for c in cells:
                if c["row"] == row and c["blur"] == blur and c["after_2"] is not None:
                    by[c["weights"]][c["seed"]] = c["after_2"]
            common = sorted(set.intersection(*(set(v) for v in by.values()))) if by else []
            base = [by["shipped"][s] for s in common] if "shipped" in by else []
            for which in paths:
                vals = [by[which][s] for s in common]
                entry: dict[str, Any] = {
                    "row": row,
                    "blur": blur,
                    "weights": which,
                    "seeds": len(vals),
                    "paper": target[row],
                }
                if vals:
                    mean = sum(vals) / len(vals)
                    lo, hi = bootstrap_ci(vals, level=0.9)
                    entry.update(
                        mean=mean,
                        ci90=[lo, hi],
                        over_paper=mean / target[row],
                        met=mean <= target[row],
                    )
                    head = [v for s, v in zip(common, vals, strict=True) if s < 30]
                    if head:
                        entry["mean_seeds_0_29"] = sum(head) / len(head)
                    if which != "shipped" and base:
                        r, rlo, rhi = ratio_ci(vals, base, level=0.9)
                        entry["over_shipped"] = [r, rlo, rhi]
                out.append(entry)
    return out


def curves(runs: Path) -> dict[str, Any]:
    """Each arm's training record: its validation curve, samples and wall time."""
    out: dict[str, Any] = {}
    for side in sorted(runs.glob("*/*/*__*.json")) + sorted(runs.glob("*/*/partial/*.json")):
        arm_dir = side.parent.parent if side.parent.name == "partial" else side.parent
        key = f"{arm_dir.parent.name}/{arm_dir.name}"
        meta = json.loads(side.read_text())
        t = meta.get("training", {})
        out[key] = {
            "samples_seen": t.get("samples_seen"),
            "wall_s": t.get("wall_s"),
            "first_group": t.get("first_group"),
            "workers": t.get("workers"),
            "val_mse": meta.get("val_mse"),
            "history": meta.get("history", []),
        }
    return out


def markdown(summary: list[dict[str, Any]], train: dict[str, Any], info: dict[str, Any]) -> str:
    lines = [
        "# One shot on the GPU machine: after 2 iterations against the paper's NN after 11",
        "",
        f"{info['device']}; {info['cores']} cores; {info['workers']} data workers per arm; "
        f"{info['train_seconds']:.0f} s of training per arm; evaluation seeds 0..N-1, "
        "the same for every weights file of a row.",
        "",
        "| row | blur | weights | seeds | after 2 [90 %] | / paper | ≤ paper | / shipped [90 %] "
        "| seeds 0-29 |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for e in summary:
        if "mean" not in e:
            lines.append(f"| {e['row']} | {e['blur']:g} | {e['weights']} | 0 | – | – | – | – | – |")
            continue
        rel = e.get("over_shipped")
        rel_text = f"{rel[0]:.2f} [{rel[1]:.2f}, {rel[2]:.2f}]" if rel else "–"
        lines.append(
            f"| {e['row']} | {e['blur']:g} | {e['weights']} | {e['seeds']} | {e['mean']:.2e} "
            f"[{e['ci90'][0]:.1e}, {e['ci90'][1]:.1e}] | {e['over_paper']:.2f} | "
            f"{'yes' if e['met'] else 'no'} | {rel_text} | "
            f"{e.get('mean_seeds_0_29', math.nan):.2e} |"
        )
    lines += [
        "",
        "| arm | samples | wall s | samples/s | val MSE: start → best | best at samples |",
        "|---|---|---|---|---|---|",
    ]
    for key, t in train.items():
        hist = [h for h in t["history"] if h.get("val_mse") is not None]
        start = hist[0]["val_mse"] if hist and hist[0]["samples"] == 0 else math.nan
        best = min(hist, key=lambda h: h["val_mse"]) if hist else {}
        rate = (t["samples_seen"] or 0) / t["wall_s"] if t.get("wall_s") else math.nan
        lines.append(
            f"| {key} | {t['samples_seen']} | {t['wall_s']} | {rate:.0f} | {start:.3g} → "
            f"{best.get('val_mse', math.nan):.3g} | {best.get('samples')} |"
        )
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(
        description=(__doc__ or "").splitlines()[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ap.add_argument("--out", required=True, help="folder for results.json, summary.md, tars")
    ap.add_argument("--runs", default="", help="training folders (default: OUT/../oneshot_runs)")
    ap.add_argument("--device", default="cuda")
    ap.add_argument("--arms", nargs="+", default=list(ARMS), choices=list(ARMS))
    ap.add_argument("--train-seconds", type=float, default=320.0)
    ap.add_argument("--deadline", type=float, default=500.0, help="s after ONESHOT_T0: all done")
    ap.add_argument("--seeds", type=int, default=200, help="evaluation seeds 0..N-1")
    ap.add_argument("--workers", type=int, default=0, help="data workers per arm (0: share cores)")
    ap.add_argument("--val-groups", type=int, default=48)
    ap.add_argument("--eval-every", type=int, default=40_000)
    ap.add_argument("--site", default="out/oneshot_site", help="where a dist-info may be written")
    args = ap.parse_args()

    t0 = float(os.environ.get("ONESHOT_T0") or time.time())
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs = Path(args.runs) if args.runs else out.parent / "oneshot_runs"
    ensure_entry_points(Path(args.site))
    cores = os.cpu_count() or 1
    trainers = len(ROWS) * len(args.arms)
    workers = args.workers or max(1, (cores - trainers) // trainers)
    info: dict[str, Any] = {
        "cores": cores,
        "workers": workers,
        "train_seconds": args.train_seconds,
        "device": args.device,
        "arms": {a: ARMS[a] for a in args.arms},
        "seeds_asked": args.seeds,
    }
    procs = launch(args, runs, workers)
    try:
        return run(args, info, procs, runs, out, t0, cores)
    finally:  # whatever failed, no trainer or data worker outlives this script
        for p in procs.values():
            if p.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGKILL)


def run(
    args: argparse.Namespace,
    info: dict[str, Any],
    procs: dict[str, Any],
    runs: Path,
    out: Path,
    t0: float,
    cores: int,
) -> int:
    if args.device.startswith("cuda"):
        probe = subprocess.run(
            [sys.executable, "-c", "import torch; print(torch.cuda.get_device_name(0))"],
            capture_output=True,
            text=True,
        )
        info["device"] = (probe.stdout.strip() or probe.stderr.strip()[-200:]) or args.device
    print(f"[{time.time() - t0:5.0f} s] {json.dumps(info)}", flush=True)
    codes = wait(procs, t0 + args.train_seconds + KILL_GRACE_S, t0)
    print(f"[{time.time() - t0:5.0f} s] training over: {codes}", flush=True)

    models: dict[str, dict[str, str]] = {}
    made: dict[str, str] = {}
    for scene, params in ROWS:
        row = row_name(scene, params)
        models[row] = {"shipped": str(shipped(scene, params))}
        for arm in args.arms:
            try:
                path, how = final_weights(runs / row / arm, scene, params)
            except Exception as exc:  # a broken run must not stop the others' evaluation
                path, how = None, f"{type(exc).__name__}: {exc}"
            made[f"{row}/{arm}"] = how
            if path is not None:
                models[row][arm] = str(path)
    print(f"[{time.time() - t0:5.0f} s] weights: {made}", flush=True)
    result: dict[str, Any] = {"info": info, "exit": codes, "weights": made, "models": models}
    # Written now and again after the evaluation: the weights come back even if it never ends.
    write_outputs(out, runs, args.arms, {**result, "training": curves(runs)}, None)

    cells = evaluate(models, args.seeds, t0 + args.deadline, t0, cores)
    errors = [c for c in cells if c["error"]]
    print(f"[{time.time() - t0:5.0f} s] {len(cells)} cells, {len(errors)} failed", flush=True)
    for c in errors[:5]:
        print(f"  failed: {c}", flush=True)
    try:
        summary = summarize(cells, models)
    except Exception as exc:
        summary = [{"error": f"{type(exc).__name__}: {exc}"}]
    train = curves(runs)
    result.update(summary=summary, training=train, cells=cells, wall_s=round(time.time() - t0, 1))
    try:
        text = markdown(summary, train, info)
    except Exception as exc:
        text = f"summary failed: {type(exc).__name__}: {exc}\n"
    write_outputs(out, runs, args.arms, result, text)
    print(text, flush=True)
    print(f"[{time.time() - t0:5.0f} s] done", flush=True)
    return 0


def write_outputs(
    out: Path, runs: Path, arms: list[str], result: dict[str, Any], summary: str | None
) -> None:
    """results.json, summary.md (when given) and one tar per row of each arm's weights (int8,
    with sidecar), log and training curve."""
    (out / "results.json").write_text(json.dumps(result, indent=1))
    if summary is not None:
        (out / "summary.md").write_text(summary)
    for scene, params in ROWS:
        row = row_name(scene, params)
        with tarfile.open(out / f"weights_{row}.tar", "w") as tar:
            for arm in arms:
                d = runs / row / arm
                for f in (
                    d / f"{row}.safetensors",
                    d / f"{row}.json",
                    d / "partial" / f"{row}.safetensors",
                    d / "partial" / f"{row}.json",
                    d / "log.txt",
                    d / "train_log.json",
                ):
                    if f.is_file():
                        tar.add(f, arcname=f"{arm}/{f.relative_to(d)}")


if __name__ == "__main__":
    sys.exit(main())
