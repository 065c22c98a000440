"""Issue-4 table from a `physbench bench benchmarks/resnet3d.toml` run: normalized min MSE after
2 and after 11 iterations (mean ± std over seeds) per scene, unknowns, bodies, blur and estimator.

    python benchmarks/resnet3d_table.py results/resnet3d > results/resnet3d/table.md
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd


def table(folder: str | Path) -> str:
    df = pd.read_parquet(Path(folder) / "results.parquet")
    ok = df[df.status == "ok"]
    rows = ["| scene | unknowns | bodies | blur | estimator | after 2 | after 11 | 2 / 11 | seeds |", "|---|---|---|---|---|---|---|---|---|"]
    keys = ["scene", "unknowns", "bodies", "blur", "estimator_name"]
    for key, g in ok.groupby(keys, sort=True):
        at = {n: g[g.iteration == n - 1].best_nmse for n in (2, 11)}
        m2, m11 = at[2].mean(), at[11].mean()
        rows.append(
            f"| {key[0]} | {key[1]} | {key[2]} | {key[3]:g} | {key[4]} | {m2:.2e} ± {at[2].std():.1e} | "
            f"{m11:.2e} ± {at[11].std():.1e} | {m2 / m11:.2f} | {len(at[11])} |"
        )
    failed = df[df.status != "ok"].drop_duplicates("cell")
    if len(failed):
        rows.append("")
        for key, g in failed.groupby(keys):
            rows.append(f"failed: {' '.join(map(str, key))}: {len(g)} cells ({g.error.iloc[0][:120]})")
    return "\n".join(rows)


if __name__ == "__main__":
    print(table(sys.argv[1] if len(sys.argv) > 1 else "results/resnet3d"))
