"""The sweep report: one self-contained HTML page with the title escaped, a line saying what was
run, the run log when given, the tables, failed cells and the win rate only when there are any,
and each figure embedded byte for byte."""

from __future__ import annotations

import base64
import re
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from physbench.bench.report import build
from physbench.bench.runner import read_table
from physbench.render.base import DEFAULT_RENDERER

RUN_LOG = {
    "runs": [
        {
            "started": "2024-05-01T10:00",
            "executor": "serial",
            "ran": 16,
            "skipped": 0,
            "wall_s": 1.5,
        }
    ],
    "versions": {"physbench": "9.9"},
}


@pytest.fixture
def table(compare_sweep: Any) -> pd.DataFrame:
    """16 finished cells: random and optuna(sampler=random), 8 seeds, 2 iterations."""
    return read_table(compare_sweep.baseline)


def _headings(page: str) -> list[str]:
    return re.findall(r"<h2>(.*?)</h2>", page)


def test_the_page_is_self_contained_and_embeds_each_figure(
    table: pd.DataFrame, tmp_path: Path
) -> None:
    fig = tmp_path / "a.png"
    fig.write_bytes(b"\x89PNG\r\n\x1a\nnot really")
    path = build(table, tmp_path, {"convergence": [fig], "landscape": []}, title="cmp")
    assert path == tmp_path / "report.html"
    page = path.read_text()
    src = f'src="data:image/png;base64,{base64.b64encode(fig.read_bytes()).decode()}"'
    assert page.count("<img ") == 1 and src in page and 'alt="a.png"' in page
    assert 'src="http' not in page and "<link" not in page
    # a figure kind without figures gets no section
    assert _headings(page) == [
        "Table 1 layout",
        "Next to the paper",
        "Per configuration",
        "Time to accuracy",
        "Win rate",
        "Convergence",
    ]
    assert page.startswith("<!doctype html>") and page.endswith("</body></html>\n")


def test_the_title_is_escaped_and_the_run_is_summed_up(table: pd.DataFrame, tmp_path: Path) -> None:
    page = build(table, tmp_path, {}, title="cmp <b> & co").read_text()
    assert "<title>cmp &lt;b&gt; &amp; co</title>" in page
    assert "<h1>cmp &lt;b&gt; &amp; co</h1>" in page and "<b>" not in page
    assert (
        f"<p>16 cells (0 failed), 8 seeds, 2 iterations, rendered by {DEFAULT_RENDERER}. " in page
    )


def test_the_run_log_lists_each_run_and_the_versions(table: pd.DataFrame, tmp_path: Path) -> None:
    page = build(table, tmp_path, {}, title="cmp", run_log=RUN_LOG).read_text()
    assert _headings(page)[0] == "Runs"
    assert (
        "<tr><td>2024-05-01T10:00</td><td>serial</td><td>16</td><td>0</td><td>1.5</td></tr>" in page
    )
    assert "versions: <code>{&quot;physbench&quot;: &quot;9.9&quot;}</code>" in page
    assert "Runs" not in _headings(build(table, tmp_path, {}, title="cmp").read_text())


def test_failed_cells_get_a_section(compare_sweep: Any, tmp_path: Path) -> None:
    failing = read_table(compare_sweep.variant(tmp_path, "failing"))
    page = build(failing, tmp_path, {}, title="cmp").read_text()
    assert "<p>16 cells (1 failed), 8 seeds" in page
    assert "Failed cells" in _headings(page)


def test_one_estimator_has_no_win_rate(table: pd.DataFrame, tmp_path: Path) -> None:
    one = table[table["estimator"] == "random"]
    page = build(one, tmp_path, {}, title="cmp").read_text()
    assert "<p>8 cells (0 failed), 8 seeds" in page and "Win rate" not in _headings(page)


def test_a_table_from_before_renderer_columns_is_rendered_by_the_default(
    table: pd.DataFrame, tmp_path: Path
) -> None:
    old = table.drop(columns=["renderer", "renderer_name", "renderer_options"])
    page = build(old, tmp_path, {}, title="cmp").read_text()
    assert f"iterations, rendered by {DEFAULT_RENDERER}. " in page


def test_posteriors_get_a_calibration_section(calibrated_sweep: Any, tmp_path: Path) -> None:
    from .conftest import SMC

    page = build(calibrated_sweep.table, tmp_path, {}, title="cal").read_text()
    assert _headings(page) == [
        "Table 1 layout",
        "Next to the paper",
        "Per configuration",
        "Time to accuracy",
        "Calibration",
        "Win rate",
    ]
    section = page.split("<h2>Calibration</h2>", 1)[1].split("<h2>", 1)[0]
    assert f"<td>{SMC}</td>" in section and "<td>random</td>" not in section
    assert "<th>SBC p</th>" in section
