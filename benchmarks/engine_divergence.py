"""Engine divergence: the paper scenes simulated in pymunk and Box2D with the same parameters.

For each scene and seed, the unknown parameters are drawn uniformly from their ranges (seeded), the
scene is simulated in both engines, and the two trajectories are compared
(:mod:`physbench.simulators.divergence`):

* final-position difference per body (m): mean and max over bodies and seeds;
* trajectory difference: max over frames of the per-body distance (m);
* qualitative outcome (:func:`~physbench.simulators.divergence.same_outcome`): which bodies moved,
  their order along x at the end.

    python benchmarks/engine_divergence.py [--seeds 10] [--scenes three_circles,...]

Prints a table (the numbers in docs/engines.md come from it).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable

import numpy as np

from physbench.simulators.divergence import SCENES, Comparison, compare, sensitivity


def _row(label: str, rows: list[Comparison]) -> str:
    final = np.concatenate([c.final_diff for c in rows])
    path = np.concatenate([c.path_diff for c in rows])
    same = sum(c.same for c in rows)
    return (
        f"{label:24s} {final.mean():7.3f} {np.quantile(final, 0.9):7.3f} {final.max():7.3f} "
        f"{path.max():7.3f} {same:>5d}/{len(rows):<3d}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--scenes", default=",".join(SCENES))
    args = ap.parse_args()
    runs: dict[str, Callable[[str, int], Comparison | None]] = {
        "pymunk vs box2d": compare,
        "pymunk(thr=1) vs box2d": lambda n, s: compare(n, s, velocity_threshold=1.0),
        "pymunk vs pymunk+1mm": lambda n, s: sensitivity(n, s, "pymunk"),
        "box2d vs box2d+1mm": lambda n, s: sensitivity(n, s, "box2d"),
    }
    print("final-position difference per body (m) over seeds: mean, 90th percentile, max;")
    print("path: max over frames; same: seeds with the same qualitative outcome\n")
    header = (
        f"{'scene / comparison':24s} {'mean':>7s} {'p90':>7s} {'max':>7s} {'path':>7s} {'same':>9s}"
    )
    for name in args.scenes.split(","):
        results = {
            label: [c for s in range(args.seeds) if (c := fn(name, s)) is not None]
            for label, fn in runs.items()
        }
        if not results["pymunk vs box2d"]:
            print(f"{name}: scene not available\n")
            continue
        base = results["pymunk vs box2d"]
        ms = {e: 1e3 * float(np.median([c.seconds[e] for c in base])) for e in ("pymunk", "box2d")}
        print(
            f"{name} ({len(base)} seeds; median simulate {ms['pymunk']:.1f} ms pymunk, "
            f"{ms['box2d']:.1f} ms box2d)"
        )
        print(header)
        for label, rows in results.items():
            print(_row(label, rows))
        worst = max(base, key=lambda c: c.final_diff.max())
        print(f"worst seed {worst.seed}: per body {np.round(worst.final_diff, 3).tolist()}")
        print("outcome differs for seeds:", [c.seed for c in base if not c.same] or "none", "\n")


if __name__ == "__main__":
    main()
