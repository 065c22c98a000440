"""Train every shipped resnet3d model (the rows of the paper's Table 1), in parallel.

    python benchmarks/train_resnet3d.py --device cuda --minutes 18 --workers 2 --parallel 8
    python benchmarks/train_resnet3d.py --install     # copy finished weights into the package
    python benchmarks/train_resnet3d.py --only three_circles__mass --minutes 45  # one row, CPU

Each row runs ``physbench train`` in its own process (logs in ``runs/train/NAME/log.txt``);
``--pack DIR`` writes int8 copies of the best weights so far (finished or not) into tar files of
at most 4 rows, for carrying them off a machine that is about to go away.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tarfile
import time
from pathlib import Path

#: (scene, params): every row of the paper's Table 1. bouncing_balls draws 2-6 balls per instance,
#: so one model covers every rack size; every ball is marked in turn.
ROWS: list[tuple[str, str]] = [
    ("three_circles", "mass"),
    ("three_circles", "elasticity"),
    ("three_circles", "mass,elasticity"),
    ("second_order", "mass"),
    ("second_order", "elasticity"),
    ("stacked_boxes", "mass"),
    ("stacked_boxes", "friction"),
    ("bouncing_balls", "mass"),
]
#: Training options shared by every row (recorded in each sidecar).
COMMON = [
    "--batch",
    "32",
    "--lr",
    "1e-3",
    "--blur-max",
    "4",
    "--val-groups",
    "16",
    "--eval-every",
    "20000",
    "--eval-seeds",
    "0",
    "--quiet",
]


def name(scene: str, params: str) -> str:
    return f"{scene}__{'+'.join(sorted(params.split(',')))}"


def launch(args: argparse.Namespace) -> int:
    rows = [r for r in ROWS if not args.only or name(*r) in args.only]
    if not rows:
        sys.exit(f"--only {args.only}: expected names among {[name(*r) for r in ROWS]}")
    todo, running, failed = list(rows), [], []
    while todo or running:
        while todo and len(running) < args.parallel:
            scene, params = todo.pop(0)
            out = Path(args.out) / name(scene, params)
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
                "--out",
                str(out),
                "--samples",
                str(args.samples),
                "--minutes",
                str(args.minutes),
                "--device",
                args.device,
                "--workers",
                str(args.workers),
                "--threads",
                "1",
                *COMMON,
            ]
            log = (out / "log.txt").open("a")
            print(" ".join(cmd[1:]), flush=True)
            running.append(
                (name(scene, params), subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT))
            )
        time.sleep(5)
        for item in list(running):
            code = item[1].poll()
            if code is not None:
                running.remove(item)
                print(f"{item[0]}: exit {code}", flush=True)
                if code:
                    failed.append(item[0])
    return 1 if failed else 0


def pack(args: argparse.Namespace) -> int:
    """int8 copies of each row's final (else best-so-far) weights, sidecars included."""
    from physbench.estimators.resnet3d import weights

    stage = Path(args.pack) / "stage"
    stage.mkdir(parents=True, exist_ok=True)
    names = []
    for run in sorted(Path(args.out).iterdir()):
        final = run / f"{run.name}.safetensors"
        if final.is_file():
            shutil.copy(final, stage / final.name)
            shutil.copy(final.with_suffix(".json"), stage / f"{run.name}.json")
        elif (run / "best.safetensors").is_file():
            state, _ = weights.load(run / "best.safetensors")
            ck = (
                json.loads((run / "checkpoint.json").read_text())
                if (run / "checkpoint.json").is_file()
                else {}
            )
            weights.save(
                stage / f"{run.name}.partial",
                weights.quantize(state),
                {"storage": weights.INT8, "history": ck.get("history", []), "unfinished": True},
            )
        else:
            continue
        if (run / "log.txt").is_file():
            shutil.copy(run / "log.txt", stage / f"{run.name}.log.txt")
        names.append(run.name)
        ck = run / "checkpoint.json"
        last = json.loads(ck.read_text())["history"][-1] if ck.is_file() else {}
        print(f"{run.name}: {'finished' if final.is_file() else 'running'} {last}")
    for k in range(0, len(names), 4):
        with tarfile.open(Path(args.pack) / f"weights{k // 4}.tar", "w") as tar:
            for f in sorted(stage.iterdir()):
                if f.name.split(".")[0] in names[k : k + 4]:
                    tar.add(f, arcname=f.name)
    shutil.rmtree(stage)
    print(f"packed {len(names)} rows into {args.pack}")
    return 0


def install(args: argparse.Namespace) -> int:
    from physbench.estimators.resnet3d import weights

    n = 0
    for run in sorted(Path(args.out).iterdir()):
        final = run / f"{run.name}.safetensors"
        if final.is_file() and (not args.only or run.name in args.only):
            shutil.copy(final, weights.SHIPPED / final.name)
            shutil.copy(final.with_suffix(".json"), weights.SHIPPED / f"{run.name}.json")
            n += 1
            print(f"installed {run.name}")
    return 0 if n else 1


def main() -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--out", default="runs/train", help="folder of the per-row training folders")
    ap.add_argument("--only", nargs="*", help="row names (SCENE__PARAMS) to train or install")
    ap.add_argument("--device", default="cpu")
    ap.add_argument("--minutes", type=float, default=0.0, help="wall-clock budget per row")
    ap.add_argument("--samples", type=int, default=5_000_000, help="sample budget per row")
    ap.add_argument("--workers", type=int, default=1, help="data processes per row")
    ap.add_argument("--parallel", type=int, default=1, help="rows trained at once")
    ap.add_argument(
        "--pack", help="write int8 tar files of the weights so far into this folder and exit"
    )
    ap.add_argument(
        "--install", action="store_true", help="copy finished weights into the package and exit"
    )
    args = ap.parse_args()
    if args.pack:
        return pack(args)
    if args.install:
        return install(args)
    return launch(args)


if __name__ == "__main__":
    sys.exit(main())
