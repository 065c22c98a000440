"""The summary files of a sweep, written next to its ``results.parquet``: the per-configuration
statistics, the paper's Table 1 layout (CSV, Markdown, LaTeX) and the time to accuracy; the
tables themselves come from :mod:`physbench.bench.tables` and
:mod:`physbench.bench.time_to_accuracy`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from physbench.bench import time_to_accuracy
from physbench.bench.tables import (
    BOOTSTRAP,
    CALIBRATION_NOTE,
    calibration,
    detail,
    latex,
    markdown,
    paper_layout,
    side_by_side,
    stats,
)

if TYPE_CHECKING:
    import pandas as pd


def write_summary(
    df: pd.DataFrame, out: Path, *, title: str, threshold: float | None = None
) -> pd.DataFrame:
    """Write ``stats.csv`` (numbers), ``time_to_accuracy.csv``
    (:mod:`physbench.bench.time_to_accuracy`), ``summary.csv`` / ``summary.md`` / ``summary.tex``
    (the paper's layout; the Markdown adds the per-configuration details and the time to
    accuracy, to ``threshold`` when given, else to the paper's value); returns the stats. Called
    by ``physbench bench`` after a sweep and by ``physbench plot``, which rebuilds them from
    ``results.parquet`` alone."""
    st = stats(df)
    tta = time_to_accuracy.table(df, threshold=threshold)
    layout = paper_layout(st)
    iters = ", ".join(str(i) for i in dict.fromkeys(st["iterations"]))
    caption = (
        f"{title}: normalized min MSE after {iters} iterations, mean ± std over seeds "
        "(paper: Link et al. 2022, Table 1, 10 seeds)"
    )
    _atomic(out / "stats.csv", st.to_csv(index=False))
    _atomic(out / "time_to_accuracy.csv", tta.to_csv(index=False))
    _atomic(out / "summary.csv", layout.to_csv(index=False))
    _atomic(out / "summary.tex", latex(layout, caption=caption))
    md = [
        f"# {title}\n",
        f"{caption}.\n",
        markdown(layout),
        "\n## Next to the paper\n",
        "The same means ± std, a row per scene and unknown set.\n",
        markdown(side_by_side(st)),
        "\n## Per configuration\n",
        "Normalized min MSE after N iterations over seeds: mean ± sample std, median, "
        f"95 % BCa bootstrap interval of the mean ({BOOTSTRAP} resamples), cells that ran "
        "(n) and failed.\n",
        markdown(detail(st)),
    ]
    if len(tta):
        md += [
            "\n## Time to accuracy\n",
            time_to_accuracy.NOTE + "\n",
            markdown(time_to_accuracy.formatted(tta)),
        ]
    cal = calibration(st)
    if len(cal):
        md += [
            "\n## Calibration\n",
            CALIBRATION_NOTE + "\n",
            markdown(cal),
        ]
    failed = st[st["failed"] > 0]
    if len(failed):
        md += [
            "\n## Failed cells\n",
            markdown(failed[["scene", "unknowns", "estimator", "failed", "error"]]),
        ]
    _atomic(out / "summary.md", "\n".join(md))
    return st


def _atomic(path: Path, text: str) -> None:
    from physbench.bench.store import atomic_write

    atomic_write(path, text.encode())
