"""One self-contained HTML page for a sweep: its settings, the Table 1 layout, per-configuration
statistics, the time to accuracy, the posteriors' calibration (when some estimator returned one),
failures, the win-rate matrix and every figure (PNG embedded as base64), so the file can be mailed
or committed and opened anywhere."""

from __future__ import annotations

import html
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from physbench.errors import counted
from physbench.plotting.embed import png_data_uri

if TYPE_CHECKING:
    import pandas as pd

CSS = """
body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:0.5em 0 1.5em;font-size:0.85em}
th,td{border:1px solid #ccc;padding:0.25em 0.6em;text-align:right}
th{background:#f0f0f0} td:first-child,th:first-child{text-align:left}
img{max-width:100%;border:1px solid #eee;margin:0.3em 0}
code{background:#f4f4f4;padding:0 0.2em} .note{color:#555;font-size:0.9em}
"""


def _table(df: pd.DataFrame) -> str:
    return df.to_html(index=False, border=0, na_rep="-", escape=True)


def _img(path: Path) -> str:
    return f'<figure><img alt="{html.escape(path.name)}" src="{png_data_uri(path)}"></figure>'


def build(
    df: pd.DataFrame,
    out: Path,
    figures: Mapping[str, Sequence[Path]],
    *,
    title: str,
    run_log: Mapping[str, Any] | None = None,
    threshold: float | None = None,
) -> Path:
    """Write ``out/report.html`` from the long table ``df`` and the figure files (the time to
    accuracy to ``threshold`` when given, else to the paper's value); returns its path."""
    from physbench.bench.store import atomic_write
    from physbench.bench.tables import final_rows, stats, upgrade

    df = upgrade(df)
    st = stats(df)
    fin = final_rows(df)
    parts = [
        f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
        f"<style>{CSS}</style></head><body><h1>{html.escape(title)}</h1>",
        _summary(df, st, fin),
        *_runs(run_log),
        *_score_tables(st),
        *_time_to_accuracy(df, threshold),
        *_calibration(st),
        *_failed_cells(st),
        *_win_rate(fin),
        *_figures(figures),
        "</body></html>\n",
    ]
    path = out / "report.html"
    atomic_write(path, "\n".join(parts).encode())
    return path


def _summary(df: pd.DataFrame, st: pd.DataFrame, fin: pd.DataFrame) -> str:
    """The sweep in one paragraph: cells, failures, seeds, iterations, renderers and the score."""
    cells, failed = len(fin), int((fin["status"] != "ok").sum())
    iters = ", ".join(str(i) for i in dict.fromkeys(st["iterations"]))
    renderers = ", ".join(html.escape(str(r)) for r in dict.fromkeys(df["renderer"]))
    return (
        f"<p>{counted(cells, 'cell')} ({failed} failed), "
        f"{counted(fin['seed'].nunique(), 'seed')}, {iters} iterations, "
        f"rendered by {renderers}. Score: normalized min MSE of the best-by-image-MSE iterate "
        "(the paper's Table 1 metric).</p>"
    )


def _runs(run_log: Mapping[str, Any] | None) -> list[str]:
    """The runs of the sweep and the versions they ran with, from its run log."""
    if not run_log:
        return []
    runs = run_log.get("runs", [])
    rows = "".join(
        f"<tr><td>{html.escape(str(r.get('started')))}</td>"
        f"<td>{html.escape(str(r.get('executor')))}</td>"
        f"<td>{r.get('ran')}</td><td>{r.get('skipped')}</td><td>{r.get('wall_s')}</td></tr>"
        for r in runs
    )
    parts = [
        "<h2>Runs</h2><table><tr><th>started</th><th>executor</th><th>cells run</th>"
        f"<th>skipped</th><th>wall s</th></tr>{rows}</table>"
    ]
    if run_log.get("versions"):
        versions = html.escape(json.dumps(run_log["versions"]))
        parts.append(f"<p class='note'>versions: <code>{versions}</code></p>")
    return parts


def _score_tables(st: pd.DataFrame) -> list[str]:
    """The Table 1 layout, the comparison with the paper and the per-configuration statistics."""
    from physbench.bench.tables import detail, paper_layout, side_by_side

    return [
        "<h2>Table 1 layout</h2><p class='note'>mean ± sample std over seeds; paper rows: Link, "
        "Schwarz, Behnke (IJCNN 2022), Table 1, 11 iterations, 10 seeds.</p>",
        _table(paper_layout(st)),
        "<h2>Next to the paper</h2>",
        _table(side_by_side(st)),
        "<h2>Per configuration</h2><p class='note'>median and 95 % BCa bootstrap interval "
        "of the mean over seeds.</p>",
        _table(detail(st)),
    ]


def _time_to_accuracy(df: pd.DataFrame, threshold: float | None) -> list[str]:
    """The time to accuracy, when any cell has one."""
    from physbench.bench import time_to_accuracy

    tta = time_to_accuracy.table(df, threshold=threshold)
    if not len(tta):
        return []
    return [
        f"<h2>Time to accuracy</h2><p class='note'>{html.escape(time_to_accuracy.NOTE)}</p>",
        _table(time_to_accuracy.formatted(tta)),
    ]


def _calibration(st: pd.DataFrame) -> list[str]:
    """The posteriors' calibration, when some estimator returned one."""
    from physbench.bench.tables import CALIBRATION_NOTE, calibration

    cal = calibration(st)
    if not len(cal):
        return []
    return [f"<h2>Calibration</h2><p class='note'>{html.escape(CALIBRATION_NOTE)}</p>", _table(cal)]


def _failed_cells(st: pd.DataFrame) -> list[str]:
    """The configurations with failed cells and their errors."""
    bad = st[st["failed"] > 0]
    if not len(bad):
        return []
    return [
        "<h2>Failed cells</h2>",
        _table(bad[["scene", "unknowns", "estimator", "failed", "error"]]),
    ]


def _win_rate(fin: pd.DataFrame) -> list[str]:
    """The win-rate matrix, when there are at least two estimators."""
    from physbench.bench.tables import win_rate_table

    wr, _ = win_rate_table(fin)
    if len(wr) <= 1:
        return []
    shown = wr.map(lambda v: "-" if v != v else f"{100 * v:.0f}%")
    shown.insert(0, "estimator", wr.index)
    return [
        "<h2>Win rate</h2><p class='note'>share of matched cells (same configuration and "
        "seed) where the row estimator ends with a lower normalized min MSE than the column "
        "(ties: half).</p>",
        _table(shown),
    ]


def _figures(figures: Mapping[str, Sequence[Path]]) -> list[str]:
    """Each non-empty group of figures under its name, embedded."""
    parts: list[str] = []
    for name, paths in figures.items():
        if paths:
            parts.append(f"<h2>{html.escape(name.capitalize())}</h2>")
            parts += [_img(p) for p in paths]
    return parts
