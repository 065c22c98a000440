"""Issue 4's generalisation check: one bouncing_balls model for 1 to 6 unknown balls.

A rack of 6 balls (held-out seeds 0..9); the first k balls' masses are unknown, the others keep
the scene's values. Prints a Markdown table of normalized min MSE after 2 and 11 iterations.

    python benchmarks/resnet3d_balls.py > results/resnet3d/balls.md
"""

from __future__ import annotations

import sys

import numpy as np

from physbench.bench.held_out import evaluate_weights
from physbench.estimators.resnet3d import weights


def main(seeds: int = 10) -> int:
    info = weights.find("bouncing_balls", ("mass",))
    print("| unknown balls (of 6) | after 2 | after 11 | 2 / 11 | seeds |\n|---|---|---|---|---|")
    for k in range(1, 7):
        rows = evaluate_weights(
            info.path,
            range(seeds),
            iterations=11,
            scene_options={"n_balls": 6},
            bodies=[f"b{i}" for i in range(k)],
        )
        a2, a11 = (np.array([r[n] for r in rows]) for n in (2, 11))
        print(
            f"| {k} | {a2.mean():.2e} ± {a2.std(ddof=1):.1e} | "
            f"{a11.mean():.2e} ± {a11.std(ddof=1):.1e} | "
            f"{a2.mean() / a11.mean():.2f} | {seeds} |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 10))
