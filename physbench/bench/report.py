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
    from physbench.bench import time_to_accuracy
    from physbench.bench.store import atomic_write
    from physbench.bench.tables import (
        CALIBRATION_NOTE,
        calibration,
        detail,
        final_rows,
        paper_layout,
        side_by_side,
        stats,
        upgrade,
        win_rate_table,
    )

    df = upgrade(df)
    st = stats(df)
    parts = [
        f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
        f"<style>{CSS}</style></head><body><h1>{html.escape(title)}</h1>",
    ]
    fin = final_rows(df)
    cells, failed = len(fin), int((fin["status"] != "ok").sum())
    iters = ", ".join(str(i) for i in dict.fromkeys(st["iterations"]))
    renderers = ", ".join(html.escape(str(r)) for r in dict.fromkeys(df["renderer"]))
    parts.append(
        f"<p>{counted(cells, 'cell')} ({failed} failed), "
        f"{counted(fin['seed'].nunique(), 'seed')}, {iters} iterations, "
        f"rendered by {renderers}. Score: normalized min MSE of the best-by-image-MSE iterate "
        "(the paper's Table 1 metric).</p>"
    )
    if run_log:
        runs = run_log.get("runs", [])
        rows = "".join(
            f"<tr><td>{html.escape(str(r.get('started')))}</td>"
            f"<td>{html.escape(str(r.get('executor')))}</td>"
            f"<td>{r.get('ran')}</td><td>{r.get('skipped')}</td><td>{r.get('wall_s')}</td></tr>"
            for r in runs
        )
        parts.append(
            "<h2>Runs</h2><table><tr><th>started</th><th>executor</th><th>cells run</th>"
            f"<th>skipped</th><th>wall s</th></tr>{rows}</table>"
        )
        if run_log.get("versions"):
            versions = html.escape(json.dumps(run_log["versions"]))
            parts.append(f"<p class='note'>versions: <code>{versions}</code></p>")
    parts += [
        "<h2>Table 1 layout</h2><p class='note'>mean ± sample std over seeds; paper rows: Link, "
        "Schwarz, Behnke (IJCNN 2022), Table 1, 11 iterations, 10 seeds.</p>",
        _table(paper_layout(st)),
    ]
    parts += ["<h2>Next to the paper</h2>", _table(side_by_side(st))]
    parts += [
        "<h2>Per configuration</h2><p class='note'>median and 95 % BCa bootstrap interval "
        "of the mean over seeds.</p>",
        _table(detail(st)),
    ]
    tta = time_to_accuracy.table(df, threshold=threshold)
    if len(tta):
        parts += [
            f"<h2>Time to accuracy</h2><p class='note'>{html.escape(time_to_accuracy.NOTE)}</p>",
            _table(time_to_accuracy.formatted(tta)),
        ]
    cal = calibration(st)
    if len(cal):
        parts += [
            f"<h2>Calibration</h2><p class='note'>{html.escape(CALIBRATION_NOTE)}</p>",
            _table(cal),
        ]
    bad = st[st["failed"] > 0]
    if len(bad):
        parts += [
            "<h2>Failed cells</h2>",
            _table(bad[["scene", "unknowns", "estimator", "failed", "error"]]),
        ]
    wr, _ = win_rate_table(fin)
    if len(wr) > 1:
        shown = wr.map(lambda v: "-" if v != v else f"{100 * v:.0f}%")
        shown.insert(0, "estimator", wr.index)
        parts += [
            "<h2>Win rate</h2><p class='note'>share of matched cells (same configuration and "
            "seed) where the row estimator ends with a lower normalized min MSE than the column "
            "(ties: half).</p>",
            _table(shown),
        ]
    for name, paths in figures.items():
        if paths:
            parts.append(f"<h2>{html.escape(name.capitalize())}</h2>")
            parts += [_img(p) for p in paths]
    parts.append("</body></html>\n")
    path = out / "report.html"
    atomic_write(path, "\n".join(parts).encode())
    return path
